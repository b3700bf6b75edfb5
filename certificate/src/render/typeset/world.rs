//! The one door through which Typst sees anything (its `World`): the template as the main
//! source, the certificate's JSON at `/certificate.json`, the laboratory's logo, the fonts
//! built into the binary, and a fixed date. Nothing is read from disk or the network here.

use ::typst::diag::{FileError, FileResult};
use ::typst::foundations::{Bytes, Datetime, Dict, IntoValue};
use ::typst::syntax::{FileId, RootedPath, Source, VirtualPath, VirtualRoot};
use ::typst::text::{Font, FontBook};
use ::typst::utils::LazyHash;
use ::typst::{Library, LibraryExt, World};
use std::collections::HashMap;
use std::sync::OnceLock;

/// The virtual path of the certificate's data, as templates read it (`json("/certificate.json")`).
pub const DATA_PATH: &str = "/certificate.json";

/// The fonts every certificate is typeset with: DejaVu Sans (regular, bold, oblique), built
/// into the binary, so that a certificate looks the same on every machine.
fn fonts() -> &'static (LazyHash<FontBook>, Vec<Font>) {
    static FONTS: OnceLock<(LazyHash<FontBook>, Vec<Font>)> = OnceLock::new();
    FONTS.get_or_init(|| {
        let faces: Vec<Font> = [
            dejavu::sans::regular(),
            dejavu::sans::bold(),
            dejavu::sans::oblique(),
            dejavu::sans::bold_oblique(),
        ]
        .into_iter()
        .flat_map(|data| Font::iter(Bytes::new(data)))
        .collect();
        (LazyHash::new(FontBook::from_fonts(&faces)), faces)
    })
}

fn file_id(path: &str) -> Option<FileId> {
    let vpath = VirtualPath::new(path).ok()?;
    Some(RootedPath::new(VirtualRoot::Project, vpath).intern())
}

/// A certificate's world: one template, its data, its files.
pub struct CertWorld {
    library: LazyHash<Library>,
    main: Source,
    files: HashMap<FileId, Bytes>,
    today: Datetime,
}

impl CertWorld {
    /// A world whose main source is `template` (shown in diagnostics as `template_name`),
    /// with `data` at [`DATA_PATH`], `files` at their virtual paths (`/logo.png`) and
    /// `inputs` as `sys.inputs`; `today` is the date of issue.
    pub fn new(
        template: &str,
        data: String,
        files: Vec<(String, Vec<u8>)>,
        inputs: Vec<(&str, String)>,
        today: (i32, u8, u8),
    ) -> Option<CertWorld> {
        let main_id = file_id("/main.typ")?;
        let mut map = HashMap::new();
        map.insert(file_id(DATA_PATH)?, Bytes::from_string(data));
        for (path, bytes) in files {
            map.insert(file_id(&path)?, Bytes::new(bytes));
        }
        let mut dict = Dict::new();
        for (k, v) in inputs {
            dict.insert(k.into(), v.into_value());
        }
        Some(CertWorld {
            library: LazyHash::new(Library::builder().with_inputs(dict).build()),
            main: Source::new(main_id, template.to_string()),
            files: map,
            today: Datetime::from_ymd(today.0, today.1, today.2)?,
        })
    }

    /// The template's source (for diagnostics).
    pub fn main_source(&self) -> &Source {
        &self.main
    }
}

impl World for CertWorld {
    fn library(&self) -> &LazyHash<Library> {
        &self.library
    }

    fn book(&self) -> &LazyHash<FontBook> {
        &fonts().0
    }

    fn main(&self) -> FileId {
        self.main.id()
    }

    fn source(&self, id: FileId) -> FileResult<Source> {
        if id == self.main.id() {
            return Ok(self.main.clone());
        }
        Err(FileError::NotSource)
    }

    fn file(&self, id: FileId) -> FileResult<Bytes> {
        if id == self.main.id() {
            return Ok(Bytes::from_string(self.main.text().to_string()));
        }
        self.files.get(&id).cloned().ok_or_else(|| {
            FileError::NotFound(id.get().vpath().get_with_slash().to_string().into())
        })
    }

    fn font(&self, index: usize) -> Option<Font> {
        fonts().1.get(index).cloned()
    }

    fn today(&self, _offset: Option<::typst::foundations::Duration>) -> Option<Datetime> {
        Some(self.today)
    }
}

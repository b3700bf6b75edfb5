//! The running hash of each stream, kept in the journal as the stream is written: one
//! `block` line per block of bytes written, each chaining the one before
//! (`c_k = SHA-256(c_(k-1) || block_k)`, `c_0` all zeros). A run folder that was never
//! sealed (a crash before its seal) is sealed only when its streams still match these
//! lines: an edited stream is "altered", not sealed. The chain shows a stream unchanged
//! since it was written; it does not stand against someone who rewrites the journal too
//! (the seal's signature does).

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::{self, BufRead, Read};
use std::path::Path;

/// The chain value before the first block.
pub const CHAIN_START: [u8; 32] = [0; 32];

/// One `block` line of the journal.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BlockRecord {
    /// The stream's file name (`imu.csv`).
    pub stream: String,
    /// First byte of the block in the file.
    pub offset: u64,
    /// Bytes in the block.
    pub len: u64,
    /// The chain value after it, lowercase hex.
    pub chain: String,
}

/// A journal line holding a block record (the journal's `t` and `event` beside it).
#[derive(Serialize, Deserialize)]
struct BlockLine {
    t: f64,
    event: String,
    #[serde(flatten)]
    block: BlockRecord,
}

impl BlockRecord {
    /// The journal line (`t`: the stream's last time stamp so far).
    pub fn journal_line(&self, t: f64) -> String {
        let line = BlockLine {
            t: if t.is_finite() { t } else { 0.0 },
            event: "block".into(),
            block: self.clone(),
        };
        serde_json::to_string(&line).unwrap_or_default()
    }
}

/// The chain of one stream being written: the blocks recorded so far and the one open.
#[derive(Clone)]
pub(crate) struct Chain {
    open: Sha256,
    start: u64,
    len: u64,
}

impl Chain {
    /// A chain whose next block starts at byte `start` after chain value `prev`.
    pub(crate) fn new(prev: [u8; 32], start: u64) -> Self {
        let mut open = Sha256::new();
        open.update(prev);
        Chain {
            open,
            start,
            len: 0,
        }
    }

    /// Bytes written into the open block.
    pub(crate) fn update(&mut self, bytes: &[u8]) {
        self.open.update(bytes);
        self.len += bytes.len() as u64;
    }

    /// Bytes in the open block.
    pub(crate) fn open_len(&self) -> u64 {
        self.len
    }

    /// Closes the open block (if it holds anything) and returns its record.
    pub(crate) fn record(&mut self, stream: &str) -> Option<BlockRecord> {
        if self.len == 0 {
            return None;
        }
        let (start, len) = (self.start, self.len);
        let value: [u8; 32] = std::mem::take(&mut self.open).finalize().into();
        *self = Chain::new(value, start + len);
        Some(BlockRecord {
            stream: stream.into(),
            offset: start,
            len,
            chain: hex::encode(value),
        })
    }
}

/// Every block record of a journal, by stream, in order; read a line at a time (a journal
/// may be long), other lines and a torn last line skipped.
pub fn journal_blocks(journal: &Path) -> io::Result<BTreeMap<String, Vec<BlockRecord>>> {
    let mut out: BTreeMap<String, Vec<BlockRecord>> = BTreeMap::new();
    let f = match std::fs::File::open(journal) {
        Ok(f) => f,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(out),
        Err(e) => return Err(e),
    };
    for line in io::BufReader::new(f).split(b'\n') {
        let line = line?;
        if memchr::memmem::find(&line, b"\"event\":\"block\"").is_none() {
            continue;
        }
        if let Ok(b) = serde_json::from_slice::<BlockLine>(&line) {
            out.entry(b.block.stream.clone()).or_default().push(b.block);
        }
    }
    Ok(out)
}

/// A stream read against its block records.
#[derive(Clone)]
pub struct StreamCheck {
    /// Records matched.
    pub blocks: usize,
    /// Bytes the records cover (from the start of the file).
    pub covered: u64,
    /// Bytes in the file.
    pub size: u64,
    /// The chain value after the last record.
    pub chain: [u8; 32],
    /// SHA-256 of the covered bytes, to go on with.
    pub(crate) covered_hash: Sha256,
}

impl std::fmt::Debug for StreamCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamCheck")
            .field("blocks", &self.blocks)
            .field("covered", &self.covered)
            .field("size", &self.size)
            .finish_non_exhaustive()
    }
}

impl StreamCheck {
    /// Bytes after the last record (written but never recorded: a crash's tail).
    pub fn tail(&self) -> u64 {
        self.size - self.covered
    }
}

/// Reads the stream at `path` (streaming) against `records`: `Ok(Err(why))` when it does
/// not match them (altered), `Ok(Ok(check))` when every recorded block is as written.
pub fn check_stream(
    path: &Path,
    records: &[BlockRecord],
) -> io::Result<Result<StreamCheck, String>> {
    crate::regular(path)?;
    let mut f = io::BufReader::with_capacity(1 << 16, std::fs::File::open(path)?);
    let size = std::fs::metadata(path)?.len();
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut covered_hash = Sha256::new();
    let mut chain = CHAIN_START;
    let mut covered = 0u64;
    let mut buf = vec![0u8; 1 << 16];
    for (k, r) in records.iter().enumerate() {
        if r.offset != covered {
            return Ok(Err(format!(
                "the journal's block {} of {name} starts at byte {}, not {covered}",
                k + 1,
                r.offset
            )));
        }
        if covered + r.len > size {
            return Ok(Err(format!(
                "{name} holds {size} bytes; the journal recorded {} written",
                covered + r.len
            )));
        }
        let mut h = Sha256::new();
        h.update(chain);
        let mut left = r.len;
        while left > 0 {
            let want = left.min(buf.len() as u64) as usize;
            f.read_exact(&mut buf[..want])?;
            h.update(&buf[..want]);
            covered_hash.update(&buf[..want]);
            left -= want as u64;
        }
        chain = h.finalize().into();
        if !hex::encode(chain).eq_ignore_ascii_case(&r.chain) {
            return Ok(Err(format!(
                "bytes {}..{} of {name} are not those written (the journal's running hash differs)",
                r.offset,
                r.offset + r.len
            )));
        }
        covered += r.len;
    }
    Ok(Ok(StreamCheck {
        blocks: records.len(),
        covered,
        size,
        chain,
        covered_hash,
    }))
}

/// Every stream of a folder that ended (`imu.csv`, `table.csv`) against the journal:
/// `Err(why)` names the first one that does not match or holds bytes never recorded.
pub fn check_folder(dir: &Path) -> io::Result<Result<(), String>> {
    let blocks = journal_blocks(&dir.join("journal.jsonl"))?;
    for name in ["imu.csv", "table.csv"] {
        let Some(records) = blocks.get(name) else {
            return Ok(Err(format!(
                "the journal keeps no running hash of {name} (written by an older ratecal)"
            )));
        };
        match check_stream(&dir.join(name), records)? {
            Err(why) => return Ok(Err(why)),
            Ok(c) if c.tail() > 0 => {
                return Ok(Err(format!(
                    "{name} holds {} bytes after the last the journal recorded",
                    c.tail()
                )));
            }
            Ok(_) => {}
        }
    }
    Ok(Ok(()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stream_matches_its_records_until_a_byte_changes() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("imu.csv");
        let data = b"t,ax\n0.1,1\n0.2,2\n0.3,3\n";
        let mut c = Chain::new(CHAIN_START, 0);
        c.update(&data[..11]);
        let r1 = c.record("imu.csv").unwrap();
        c.update(&data[11..]);
        let r2 = c.record("imu.csv").unwrap();
        assert!(c.record("imu.csv").is_none());
        assert_eq!((r2.offset, r2.len), (11, data.len() as u64 - 11));
        let records = vec![r1, r2];
        std::fs::write(&path, data).unwrap();
        let ok = check_stream(&path, &records).unwrap().unwrap();
        assert_eq!((ok.covered, ok.tail()), (data.len() as u64, 0));
        // A tail never recorded is told apart; an edited byte is altered.
        std::fs::write(&path, [&data[..], b"0.4,4\n"].concat()).unwrap();
        assert_eq!(check_stream(&path, &records).unwrap().unwrap().tail(), 6);
        std::fs::write(&path, b"t,ax\n0.1,1\n0.2,9\n0.3,3\n").unwrap();
        let why = check_stream(&path, &records).unwrap().unwrap_err();
        assert!(why.contains("bytes 11..23"), "{why}");
        // Round trip through a journal line.
        let line = records[0].journal_line(0.1);
        let j = tmp.path().join("journal.jsonl");
        std::fs::write(
            &j,
            format!("{{\"t\":0,\"event\":\"start\"}}\n{line}\n{{\"t\":0,"),
        )
        .unwrap();
        assert_eq!(journal_blocks(&j).unwrap()["imu.csv"], records[..1]);
    }
}

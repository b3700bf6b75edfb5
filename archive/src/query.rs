//! Finding runs: `list` with filters, `show` of one run (by id, unique id prefix, or the
//! run's own name).

use crate::{Archive, ArchiveError, Result};
use serde::Serialize;
use sqlx::Arguments;
use sqlx::AssertSqlSafe;
use sqlx::any::AnyArguments;

/// Which runs to list; `None` fields do not filter.
#[derive(Debug, Clone, Default)]
pub struct Filter {
    /// IMU serial.
    pub serial: Option<String>,
    /// IMU model.
    pub model: Option<String>,
    /// Procedure name.
    pub procedure: Option<String>,
    /// Started at or after (RFC 3339 or date; compared as UTC text).
    pub since: Option<String>,
    /// Started at or before (a bare date includes that whole day).
    pub until: Option<String>,
    /// `pass`, `fail`, `incomplete` or `aborted`.
    pub verdict: Option<String>,
    /// Dry runs too.
    pub include_dry_runs: bool,
}

/// One run in a list; the JSON keys are a stable interface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummary {
    /// Archive id (content address).
    pub id: String,
    /// IMU serial (`unknown` when the manifest had none).
    pub serial: String,
    /// IMU model.
    pub model: String,
    /// Procedure name.
    pub procedure: String,
    /// Procedure version.
    pub version: String,
    /// Start, RFC 3339 UTC.
    pub started: String,
    /// `pass`, `fail`, `incomplete` or `aborted`.
    pub verdict: String,
    /// Simulated station.
    pub dry_run: bool,
    /// The run's own name (its folder name when it ran).
    pub name: String,
    /// Station.
    pub station: String,
    /// Operator.
    pub operator: Option<String>,
}

/// A stored file of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StoredFile {
    /// Path in the run folder.
    pub path: String,
    /// SHA-256.
    pub sha256: String,
    /// Bytes.
    pub size: i64,
}

/// Everything the index holds about one run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunDetail {
    /// The list fields.
    #[serde(flatten)]
    pub summary: RunSummary,
    /// Procedure canonical SHA-256.
    pub procedure_sha256: String,
    /// End, if recorded.
    pub ended: Option<String>,
    /// Run status.
    pub status: String,
    /// Lab conditions.
    pub environment: serde_json::Value,
    /// The manifest's IMU block.
    pub imu: serde_json::Value,
    /// Parameters: name, value, u, unit.
    pub parameters: Vec<crate::ParamRow>,
    /// Stored files.
    pub files: Vec<StoredFile>,
}

impl serde::Serialize for crate::ParamRow {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("Parameter", 4)?;
        st.serialize_field("name", &self.name)?;
        st.serialize_field("value", &self.value)?;
        st.serialize_field("u", &self.u)?;
        st.serialize_field("unit", &self.unit)?;
        st.end()
    }
}

const SUMMARY_COLUMNS: &str =
    "id, serial, model, procedure, version, started, verdict, dry_run, name, station, operator";

type SummaryRow = (
    String,
    String,
    String,
    String,
    String,
    String,
    String,
    i64,
    String,
    String,
    Option<String>,
);

fn summary(r: SummaryRow) -> RunSummary {
    RunSummary {
        id: r.0,
        serial: r.1,
        model: r.2,
        procedure: r.3,
        version: r.4,
        started: r.5,
        verdict: r.6,
        dry_run: r.7 != 0,
        name: r.8,
        station: r.9,
        operator: r.10,
    }
}

impl Archive {
    /// Runs matching `f`, oldest first.
    pub async fn list(&self, f: &Filter) -> Result<Vec<RunSummary>> {
        let mut sql = format!("SELECT {SUMMARY_COLUMNS} FROM runs WHERE 1 = 1");
        let mut args = AnyArguments::default();
        let mut n = 0;
        let mut add = |sql: &mut String, cond: &str, v: String| {
            n += 1;
            sql.push_str(&format!(" AND {cond} ${n}"));
            let _ = args.add(v);
        };
        if let Some(s) = &f.serial {
            add(&mut sql, "serial =", s.clone());
        }
        if let Some(s) = &f.model {
            add(&mut sql, "model =", s.clone());
        }
        if let Some(s) = &f.procedure {
            add(&mut sql, "procedure =", s.clone());
        }
        if let Some(s) = &f.verdict {
            add(&mut sql, "verdict =", s.clone());
        }
        if let Some(s) = &f.since {
            add(&mut sql, "started >=", s.clone());
        }
        if let Some(s) = &f.until {
            // A bare date includes its whole day ('~' sorts after every time character).
            let bound = if s.len() == 10 {
                format!("{s}~")
            } else {
                s.clone()
            };
            add(&mut sql, "started <=", bound);
        }
        if !f.include_dry_runs {
            sql.push_str(" AND dry_run = 0");
        }
        sql.push_str(" ORDER BY started, id");
        let rows: Vec<SummaryRow> = sqlx::query_as_with(AssertSqlSafe(sql), args)
            .fetch_all(&self.pool)
            .await?;
        Ok(rows.into_iter().map(summary).collect())
    }

    /// The archive id `key` names: an id, a unique id prefix (4+ characters) or a run name.
    pub async fn resolve(&self, key: &str) -> Result<String> {
        let prefix = if key.len() >= 4 && key.chars().all(|c| c.is_ascii_hexdigit()) {
            format!("{}%", key.to_ascii_lowercase())
        } else {
            // Matches no id: ids are hex.
            "-".to_string()
        };
        let rows: Vec<(String,)> = sqlx::query_as(
            "SELECT id FROM runs WHERE id = $1 OR name = $1 OR id LIKE $2 ORDER BY id",
        )
        .bind(key)
        .bind(prefix)
        .fetch_all(&self.pool)
        .await?;
        match rows.len() {
            0 => Err(ArchiveError::NoSuchRun(key.to_string())),
            1 => Ok(rows[0].0.clone()),
            _ => Err(ArchiveError::Ambiguous(
                key.to_string(),
                rows.iter()
                    .map(|r| r.0.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            )),
        }
    }

    /// Everything the index holds about the run `key` names.
    pub async fn show(&self, key: &str) -> Result<RunDetail> {
        let id = self.resolve(key).await?;
        let sql = format!("SELECT {SUMMARY_COLUMNS} FROM runs WHERE id = $1");
        let row: SummaryRow = sqlx::query_as(AssertSqlSafe(sql))
            .bind(&id)
            .fetch_one(&self.pool)
            .await?;
        type More = (
            String,
            Option<String>,
            String,
            Option<f64>,
            Option<f64>,
            Option<f64>,
            Option<f64>,
            String,
        );
        let more: More = sqlx::query_as(
            "SELECT procedure_sha256, ended, status, temperature_c, humidity_pct, pressure_kpa, \
             vibration_g, imu FROM runs WHERE id = $1",
        )
        .bind(&id)
        .fetch_one(&self.pool)
        .await?;
        let parameters = self.parameters_of(&id).await?;
        let files = self.files_of(&id).await?;
        Ok(RunDetail {
            summary: summary(row),
            procedure_sha256: more.0,
            ended: more.1,
            status: more.2,
            environment: serde_json::json!({
                "temperature_c": more.3,
                "humidity_pct": more.4,
                "pressure_kpa": more.5,
                "vibration_g": more.6,
            }),
            imu: serde_json::from_str(&more.7).unwrap_or(serde_json::Value::Null),
            parameters,
            files,
        })
    }

    /// The parameters of run `id`, by name.
    pub async fn parameters_of(&self, id: &str) -> Result<Vec<crate::ParamRow>> {
        let rows: Vec<(String, f64, f64, String)> = sqlx::query_as(
            "SELECT name, value, u, unit FROM parameters WHERE run_id = $1 ORDER BY name",
        )
        .bind(id)
        .fetch_all(&self.pool)
        .await?;
        Ok(rows
            .into_iter()
            .map(|(name, value, u, unit)| crate::ParamRow {
                name,
                value,
                u,
                unit,
            })
            .collect())
    }

    /// The stored files of run `id`, by path.
    pub async fn files_of(&self, id: &str) -> Result<Vec<StoredFile>> {
        let rows: Vec<(String, String, i64)> = sqlx::query_as(
            "SELECT path, sha256, size FROM run_files WHERE run_id = $1 ORDER BY path",
        )
        .bind(id)
        .fetch_all(&self.pool)
        .await?;
        Ok(rows
            .into_iter()
            .map(|(path, sha256, size)| StoredFile { path, sha256, size })
            .collect())
    }
}

//! Certificate numbers, `PREFIX-YYYY-NNNNNN`, issued from one sequence kept in the archive
//! and bound to what was issued under them: the customer, the order, the template's hash and
//! the SHA-256 of the PDF and of the JSON.
//!
//! A number is taken in the transaction that records its document ([`Archive::reserve`]
//! inserts the row, [`Reservation::record`] completes and commits it): a process that dies
//! in between has its transaction rolled back and burns nothing. Concurrent processes never
//! share a number: the unique keys make a race collide (or wait for the writer's lock) and
//! the loser retries.

use crate::{Archive, Result};
use sqlx::Any;
use std::time::{Duration, Instant};

/// A certificate the archive issued, as recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Issued {
    /// `PREFIX-YYYY-NNNNNN`.
    pub number: String,
    /// The archive id of the run it certifies.
    pub run_id: String,
    /// 0 for the first certificate of a run, then one more per amendment.
    pub amendment: i64,
    /// The number this one replaces (an amendment).
    pub replaces: Option<String>,
    /// When it was issued (RFC 3339).
    pub issued: String,
    /// The customer it names.
    pub customer: Option<String>,
    /// The order it names.
    pub order_ref: Option<String>,
    /// SHA-256 of the template (and logo) that typeset it.
    pub template_sha256: Option<String>,
    /// SHA-256 of its PDF.
    pub pdf_sha256: Option<String>,
    /// SHA-256 of its JSON (`--format json`).
    pub json_sha256: Option<String>,
    /// Why it amends the one it replaces.
    pub reason: Option<String>,
}

/// What a document issued under a number is bound to.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Content {
    /// The customer it names.
    pub customer: Option<String>,
    /// The order it names.
    pub order: Option<String>,
    /// SHA-256 of the template (and logo).
    pub template_sha256: String,
    /// SHA-256 of the PDF.
    pub pdf_sha256: String,
    /// SHA-256 of the JSON.
    pub json_sha256: String,
    /// An amendment's reason.
    pub reason: Option<String>,
}

/// A number taken inside an open transaction: recorded with its document by
/// [`Reservation::record`], released when dropped (or when the process dies).
pub struct Reservation {
    tx: sqlx::Transaction<'static, Any>,
    seq: i64,
    /// `PREFIX-YYYY-NNNNNN`.
    pub number: String,
    /// The number it replaces (an amendment).
    pub replaces: Option<String>,
    /// When it is issued (RFC 3339).
    pub issued: String,
}

type Row = (
    String,
    String,
    i64,
    Option<String>,
    String,
    Option<String>,
    Option<String>,
    Option<String>,
    Option<String>,
    Option<String>,
    Option<String>,
);

impl From<Row> for Issued {
    fn from(r: Row) -> Self {
        Issued {
            number: r.0,
            run_id: r.1,
            amendment: r.2,
            replaces: r.3,
            issued: r.4,
            customer: r.5,
            order_ref: r.6,
            template_sha256: r.7,
            pdf_sha256: r.8,
            json_sha256: r.9,
            reason: r.10,
        }
    }
}

macro_rules! select {
    ($where:literal) => {
        concat!(
            "SELECT number, run_id, amendment, replaces, issued, customer, order_ref, ",
            "template_sha256, pdf_sha256, json_sha256, reason FROM certificates ",
            $where
        )
    };
}

impl Archive {
    /// The newest certificate of archived run `run_id` (its last amendment), if any.
    pub async fn newest_certificate(&self, run_id: &str) -> Result<Option<Issued>> {
        let row: Option<Row> =
            sqlx::query_as(select!("WHERE run_id = $1 ORDER BY amendment DESC LIMIT 1"))
                .bind(run_id)
                .fetch_optional(&self.pool)
                .await?;
        Ok(row.map(Issued::from))
    }

    /// The certificate whose PDF has SHA-256 `sha256`, and the number that replaced it (an
    /// amendment issued later), if any.
    pub async fn certificate_of_pdf(
        &self,
        sha256: &str,
    ) -> Result<Option<(Issued, Option<String>)>> {
        let found: Option<Row> = sqlx::query_as(select!("WHERE pdf_sha256 = $1"))
            .bind(sha256)
            .fetch_optional(&self.pool)
            .await?;
        let Some(found) = found.map(Issued::from) else {
            return Ok(None);
        };
        let replaced: Option<(String,)> =
            sqlx::query_as("SELECT number FROM certificates WHERE replaces = $1")
                .bind(&found.number)
                .fetch_optional(&self.pool)
                .await?;
        Ok(Some((found, replaced.map(|r| r.0))))
    }

    /// Binds a certificate issued before the archive recorded content to `content` (its
    /// first reissue since).
    pub async fn bind_certificate(&self, number: &str, content: &Content) -> Result<()> {
        sqlx::query(
            "UPDATE certificates SET customer = $1, order_ref = $2, template_sha256 = $3, \
             pdf_sha256 = $4, json_sha256 = $5 WHERE number = $6 AND json_sha256 IS NULL",
        )
        .bind(content.customer.clone())
        .bind(content.order.clone())
        .bind(&content.template_sha256)
        .bind(&content.pdf_sha256)
        .bind(&content.json_sha256)
        .bind(number)
        .execute(&self.pool)
        .await?;
        Ok(())
    }

    /// Takes the next number of the sequence (`prefix`, `year`) for run `run_id` inside a
    /// transaction; with `amend`, it replaces the run's newest. Held until recorded or
    /// dropped; a concurrent process waits or retries. `None` when the run has a
    /// certificate and `amend` is false (another process issued it meanwhile).
    pub async fn reserve(
        &self,
        run_id: &str,
        prefix: &str,
        year: i32,
        amend: bool,
        now: &str,
    ) -> Result<Option<Reservation>> {
        let start = Instant::now();
        let mut attempt = 0u64;
        loop {
            match self.try_reserve(run_id, prefix, year, amend, now).await {
                Ok(r) => return Ok(r),
                Err(e) if start.elapsed() > Duration::from_secs(120) => return Err(e),
                Err(_) => {
                    // Another process took the number (or holds the write lock): again.
                    let ms = 5 + (attempt * 7 + std::process::id() as u64) % 20;
                    attempt += 1;
                    tokio::time::sleep(Duration::from_millis(ms)).await;
                }
            }
        }
    }

    async fn try_reserve(
        &self,
        run_id: &str,
        prefix: &str,
        year: i32,
        amend: bool,
        now: &str,
    ) -> Result<Option<Reservation>> {
        let mut tx = self.pool.begin().await?;
        let newest: Option<(String, i64)> = sqlx::query_as(
            "SELECT number, amendment FROM certificates WHERE run_id = $1 \
             ORDER BY amendment DESC LIMIT 1",
        )
        .bind(run_id)
        .fetch_optional(&mut *tx)
        .await?;
        if newest.is_some() && !amend {
            return Ok(None);
        }
        let (max,): (i64,) = sqlx::query_as("SELECT COALESCE(MAX(seq), 0) FROM certificates")
            .fetch_one(&mut *tx)
            .await?;
        let seq = max + 1;
        let number = format!("{prefix}-{year:04}-{seq:06}");
        let amendment = newest.as_ref().map_or(0, |(_, a)| a + 1);
        let replaces = newest.map(|(n, _)| n);
        sqlx::query(
            "INSERT INTO certificates (seq, number, run_id, amendment, replaces, issued) \
             VALUES ($1, $2, $3, $4, $5, $6)",
        )
        .bind(seq)
        .bind(&number)
        .bind(run_id)
        .bind(amendment)
        .bind(replaces.clone())
        .bind(now)
        .execute(&mut *tx)
        .await?;
        Ok(Some(Reservation {
            tx,
            seq,
            number,
            replaces,
            issued: now.into(),
        }))
    }
}

impl Reservation {
    /// Records the document issued under the number and commits: only now is the number
    /// taken.
    pub async fn record(mut self, content: &Content) -> Result<()> {
        sqlx::query(
            "UPDATE certificates SET customer = $1, order_ref = $2, template_sha256 = $3, \
             pdf_sha256 = $4, json_sha256 = $5, reason = $6 WHERE seq = $7",
        )
        .bind(content.customer.clone())
        .bind(content.order.clone())
        .bind(&content.template_sha256)
        .bind(&content.pdf_sha256)
        .bind(&content.json_sha256)
        .bind(content.reason.clone())
        .bind(self.seq)
        .execute(&mut *self.tx)
        .await?;
        self.tx.commit().await?;
        Ok(())
    }
}

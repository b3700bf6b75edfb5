//! Certificate numbers, `PREFIX-YYYY-NNNNNN`, issued from one sequence kept in the archive:
//! unique across concurrent processes (the unique keys make a race collide, the loser
//! retries), the same number when a run's certificate is reissued, the next one for an
//! amendment, which names the number it replaces.

use crate::{Archive, ArchiveError, Result};
use std::time::Duration;

/// A number the archive issued.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Issued {
    /// `PREFIX-YYYY-NNNNNN`.
    pub number: String,
    /// The number this one replaces (an amendment).
    pub replaces: Option<String>,
    /// False when the run already had this number (a reissue).
    pub new: bool,
    /// When the number was first issued (RFC 3339).
    pub issued: String,
}

/// A run's newest certificate: number, amendment, when issued, what it replaces.
type Newest = (String, i64, String, Option<String>);

impl Archive {
    /// The certificate number of archived run `run_id`: its newest number when it has one
    /// and `amend` is false, else the next of the sequence (`prefix`, `year`).
    pub async fn certificate_number(
        &self,
        run_id: &str,
        prefix: &str,
        year: i32,
        amend: bool,
        now: &str,
    ) -> Result<Issued> {
        let mut last = None;
        for attempt in 0..200u64 {
            match self.try_issue(run_id, prefix, year, amend, now).await {
                Ok(i) => return Ok(i),
                Err(e) => {
                    last = Some(e);
                    // Another process took the number (or holds the write lock): again.
                    let ms = 5 + (attempt * 7 + std::process::id() as u64) % 20;
                    tokio::time::sleep(Duration::from_millis(ms)).await;
                }
            }
        }
        Err(last.unwrap_or_else(|| ArchiveError::Open {
            location: self.location().into(),
            message: "no certificate number could be issued".into(),
        }))
    }

    async fn newest(&self, run_id: &str) -> Result<Option<Newest>> {
        Ok(sqlx::query_as(
            "SELECT number, amendment, issued, replaces FROM certificates WHERE run_id = $1 \
             ORDER BY amendment DESC LIMIT 1",
        )
        .bind(run_id)
        .fetch_optional(&self.pool)
        .await?)
    }

    async fn try_issue(
        &self,
        run_id: &str,
        prefix: &str,
        year: i32,
        amend: bool,
        now: &str,
    ) -> Result<Issued> {
        let newest = self.newest(run_id).await?;
        if !amend && let Some((number, _, issued, replaces)) = &newest {
            return Ok(Issued {
                number: number.clone(),
                replaces: replaces.clone(),
                new: false,
                issued: issued.clone(),
            });
        }
        let mut tx = self.pool.begin().await?;
        let (max,): (i64,) = sqlx::query_as("SELECT COALESCE(MAX(seq), 0) FROM certificates")
            .fetch_one(&mut *tx)
            .await?;
        let seq = max + 1;
        let number = format!("{prefix}-{year:04}-{seq:06}");
        let amendment = newest.as_ref().map_or(0, |(_, a, _, _)| a + 1);
        let replaces = newest.map(|(n, _, _, _)| n);
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
        tx.commit().await?;
        Ok(Issued {
            number,
            replaces,
            new: true,
            issued: now.into(),
        })
    }
}

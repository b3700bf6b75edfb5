//! Explain's result kept beside each run (`explained`, migration 0004): a query over a
//! fleet explains only the runs the archive holds no result for under the same `key` (the
//! ratecal version and the options that change the result); the body is text the archive
//! does not read.

use crate::{Archive, Result};

impl Archive {
    /// The explanation kept for run `id` under `key`, if any.
    pub async fn explained(&self, id: &str, key: &str) -> Result<Option<String>> {
        let row: Option<(String,)> =
            sqlx::query_as("SELECT body FROM explained WHERE run_id = $1 AND key = $2")
                .bind(id)
                .bind(key)
                .fetch_optional(&self.pool)
                .await?;
        Ok(row.map(|r| r.0))
    }

    /// Keeps `body` as run `id`'s explanation under `key` (replacing one kept before).
    pub async fn keep_explained(&self, id: &str, key: &str, body: &str) -> Result<()> {
        let mut tx = self.pool.begin().await?;
        sqlx::query("DELETE FROM explained WHERE run_id = $1 AND key = $2")
            .bind(id)
            .bind(key)
            .execute(&mut *tx)
            .await?;
        sqlx::query("INSERT INTO explained (run_id, key, body, created) VALUES ($1, $2, $3, $4)")
            .bind(id)
            .bind(key)
            .bind(body)
            .bind(crate::dates::now_rfc3339())
            .execute(&mut *tx)
            .await?;
        tx.commit().await?;
        Ok(())
    }
}

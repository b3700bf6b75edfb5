-- Explain's result per run (issue 40): explaining a fleet re-reads no recording whose
-- explanation the archive holds for the same analysis (`key`: the ratecal version and the
-- options that change the result). The body is explain's JSON with its profile.

CREATE TABLE explained (
    run_id TEXT NOT NULL REFERENCES runs (id),
    key TEXT NOT NULL,
    body TEXT NOT NULL,
    created TEXT NOT NULL,
    PRIMARY KEY (run_id, key)
);

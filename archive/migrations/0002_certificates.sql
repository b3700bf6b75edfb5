-- Certificate numbers: one sequence for the whole archive. A run keeps its number when its
-- certificate is reissued (amendment 0); an amended certificate takes the next number and
-- names the one it replaces. The unique keys make two processes that race for a number
-- (or for a run's first number) collide, and the loser retries.

CREATE TABLE certificates (
    seq BIGINT PRIMARY KEY,
    number TEXT NOT NULL UNIQUE,
    run_id TEXT NOT NULL REFERENCES runs (id),
    amendment BIGINT NOT NULL,
    replaces TEXT,
    issued TEXT NOT NULL,
    UNIQUE (run_id, amendment)
);

-- The archive index. Portable SQL: the same text migrates SQLite and PostgreSQL.
-- Run ids are content addresses (SHA-256 over the run's files), so adding twice is a no-op.

CREATE TABLE runs (
    id TEXT PRIMARY KEY,
    name TEXT NOT NULL,
    serial TEXT NOT NULL,
    model TEXT NOT NULL,
    procedure TEXT NOT NULL,
    version TEXT NOT NULL,
    procedure_sha256 TEXT NOT NULL,
    station TEXT NOT NULL,
    operator TEXT,
    started TEXT NOT NULL,
    ended TEXT,
    status TEXT NOT NULL,
    dry_run BIGINT NOT NULL,
    verdict TEXT NOT NULL,
    temperature_c DOUBLE PRECISION,
    humidity_pct DOUBLE PRECISION,
    pressure_kpa DOUBLE PRECISION,
    vibration_g DOUBLE PRECISION,
    imu TEXT NOT NULL,
    added TEXT NOT NULL
);

CREATE INDEX runs_serial_started ON runs (serial, started);
CREATE INDEX runs_started ON runs (started);

CREATE TABLE run_files (
    run_id TEXT NOT NULL REFERENCES runs (id),
    path TEXT NOT NULL,
    sha256 TEXT NOT NULL,
    size BIGINT NOT NULL,
    PRIMARY KEY (run_id, path)
);

CREATE INDEX run_files_sha256 ON run_files (sha256);

CREATE TABLE parameters (
    run_id TEXT NOT NULL REFERENCES runs (id),
    name TEXT NOT NULL,
    value DOUBLE PRECISION NOT NULL,
    u DOUBLE PRECISION NOT NULL,
    unit TEXT NOT NULL,
    PRIMARY KEY (run_id, name)
);

CREATE TABLE limits (
    run_id TEXT NOT NULL REFERENCES runs (id),
    quantity TEXT NOT NULL,
    op TEXT NOT NULL,
    limit_value DOUBLE PRECISION NOT NULL,
    unit TEXT NOT NULL
);

CREATE INDEX limits_run ON limits (run_id);

-- Stored files, when the archive keeps them in the database (a PostgreSQL URL without a
-- shared folder); a folder archive keeps them under files/ and leaves this table empty.
CREATE TABLE blobs (
    sha256 TEXT PRIMARY KEY,
    size BIGINT NOT NULL,
    data BYTEA NOT NULL
);

-- surfmap store, PostgreSQL dialect. Append-only: never edit a migration that has shipped.
-- Times are Unix milliseconds; booleans are 0/1 integers (the same in both dialects).
CREATE TABLE meshes (
    owner      TEXT    NOT NULL,
    id         TEXT    NOT NULL,   -- sha256 of the uploaded bytes (the blob key)
    format     TEXT    NOT NULL,
    size_bytes BIGINT NOT NULL,
    summary    TEXT    NOT NULL,   -- JSON: the `surfmap inspect` summary
    created_at BIGINT NOT NULL,
    PRIMARY KEY (owner, id)
);

CREATE TABLE jobs (
    id               TEXT    PRIMARY KEY,  -- UUIDv7: time ordered, so ORDER BY id is FIFO
    owner            TEXT    NOT NULL,
    idempotency_key  TEXT,
    request_hash     TEXT    NOT NULL,
    method           TEXT    NOT NULL,
    spec             TEXT    NOT NULL,     -- JSON JobSpec, fully resolved
    source           TEXT    NOT NULL,
    target           TEXT    NOT NULL,
    state            TEXT    NOT NULL,     -- queued | running | succeeded | failed | cancelled
    stage            TEXT    NOT NULL DEFAULT 'queued',
    progress         DOUBLE PRECISION NOT NULL DEFAULT 0,
    attempts         BIGINT NOT NULL DEFAULT 0,
    max_attempts     BIGINT NOT NULL,
    lease_owner      TEXT,
    lease_expires_at BIGINT,
    fence            BIGINT NOT NULL DEFAULT 0,
    cancel_requested BIGINT NOT NULL DEFAULT 0,
    error_code       TEXT,
    error_message    TEXT,
    result           TEXT,                 -- JSON metrics report
    artifacts        TEXT,                 -- JSON [{name, content_type, sha256, size}]
    created_at       BIGINT NOT NULL,
    updated_at       BIGINT NOT NULL,
    started_at       BIGINT,
    finished_at      BIGINT,
    UNIQUE (owner, idempotency_key)
);

CREATE INDEX jobs_state_id ON jobs (state, id);
CREATE INDEX jobs_owner_id ON jobs (owner, id);

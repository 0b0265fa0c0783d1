//! Throw-away databases for tests: a temporary SQLite file, and a fresh PostgreSQL database
//! under the server that `SURFMAP_TEST_POSTGRES_URL` names (dropped by nobody: each name is
//! unique, and CI machines are discarded).

use crate::Result;
use sqlx::postgres::PgPoolOptions;

/// The PostgreSQL URL of the test server, if the environment gives one.
pub fn postgres_base_url() -> Option<String> {
    std::env::var("SURFMAP_TEST_POSTGRES_URL").ok().filter(|s| !s.is_empty())
}

/// Creates an empty database next to the one `base` names and returns its URL.
///
/// # Errors
/// When the server refuses the connection or the `CREATE DATABASE`.
pub async fn fresh_postgres_database(base: &str) -> Result<String> {
    let pool = PgPoolOptions::new().max_connections(1).connect(base).await?;
    let name = format!("surfmap_t_{}", uuid::Uuid::new_v4().simple());
    sqlx::query(sqlx::AssertSqlSafe(format!("CREATE DATABASE {name}"))).execute(&pool).await?;
    pool.close().await;
    let (head, query) = match base.split_once('?') {
        Some((h, q)) => (h, format!("?{q}")),
        None => (base, String::new()),
    };
    let scheme_end = head.find("://").map_or(0, |i| i + 3);
    let host_part = match head[scheme_end..].find('/') {
        Some(i) => &head[..scheme_end + i],
        None => head,
    };
    Ok(format!("{host_part}/{name}{query}"))
}

/// Whether a writer could take the SQLite write lock at this instant (`BEGIN IMMEDIATE` with no
/// busy wait, rolled back at once). A process stopped with `SIGSTOP` in the middle of a commit
/// keeps that lock until it is continued, so a test that stalls a worker checks this first.
///
/// # Errors
/// When the file cannot be opened.
pub async fn sqlite_write_lock_free(url: &str) -> Result<bool> {
    use sqlx::sqlite::SqliteConnectOptions;
    use sqlx::{ConnectOptions, Connection};
    use std::str::FromStr;
    let mut conn = SqliteConnectOptions::from_str(url)?.busy_timeout(std::time::Duration::ZERO).connect().await?;
    let free = match sqlx::raw_sql("BEGIN IMMEDIATE").execute(&mut conn).await {
        Ok(_) => {
            sqlx::raw_sql("ROLLBACK").execute(&mut conn).await?;
            true
        }
        Err(sqlx::Error::Database(e)) if e.message().contains("locked") || e.message().contains("busy") => false,
        Err(e) => return Err(e.into()),
    };
    conn.close().await?;
    Ok(free)
}

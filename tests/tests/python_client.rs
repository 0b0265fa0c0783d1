//! The Python client's tests (`clients/python/tests`, pytest) against the real server binary:
//! every endpoint, errors of each kind, a failed, a cancelled job, a 100k-vertex upload, sync
//! and async. The README's test command installs pytest, httpx and the client.

mod common;

#[test]
fn python_client_against_the_real_server() {
    common::pytest("clients/python/tests", &[]);
}

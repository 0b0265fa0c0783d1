//! `deploy/smoke.sh`, the script users' CI runs against a deployment, run here against the
//! real server with in-process workers (and a bearer token, as a deployment would have).

mod common;

use common::Env;
use std::process::Command;

#[test]
fn smoke_script_passes_against_a_local_server() {
    let env = Env::sqlite();
    let (_server, base) = env.server(&["--workers", "1", "--api-token", "smoke-token"]);
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/smoke.sh");
    let out = Command::new("bash").arg(&script).arg(&base).env("SURFMAP_TOKEN", "smoke-token").output().expect("bash");
    let (so, se) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "smoke.sh failed:\n{so}\n{se}");
    assert!(so.contains("smoke: OK"), "{so}");
    assert_eq!(so.matches(": ok").count(), 8, "four checks each way: {so}");
    // Without the token the same script is refused.
    let out = Command::new("bash").arg(&script).arg(&base).output().expect("bash");
    assert!(!out.status.success());
}

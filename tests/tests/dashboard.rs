//! The dashboard in headless Chromium (Debian's package, driven by Playwright for Python):
//! `tests/ui/test_dashboard.py` starts the real server, runs a job, watches `/ui/` show it
//! succeed without a reload, checks the job page's viewer drew both meshes, and that another
//! token's page does not list the job. Screenshots go to `ui-screenshots/` in the target directory.

mod common;

#[test]
fn dashboard_in_headless_chromium() {
    common::pytest("tests/ui", &[]);
}

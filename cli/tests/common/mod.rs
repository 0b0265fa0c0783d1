//! Helpers shared by the CLI tests: the binary, the shared meshes, temp files.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `shared/meshes` beside the repository (or `$SURFMAP_SHARED/meshes`).
pub fn shared() -> PathBuf {
    let root = std::env::var_os("SURFMAP_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared"));
    assert!(root.join("meshes/README.md").exists(), "shared data not found at {} (set SURFMAP_SHARED)", root.display());
    root
}

pub fn mesh(name: &str) -> PathBuf {
    shared().join("meshes").join(name)
}

pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

pub fn surfmap(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_surfmap")).args(args).output().expect("run surfmap")
}

pub fn stdout_json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "surfmap failed: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

/// A fresh temporary directory under the target dir.
pub fn tempdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("surfmap-test-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

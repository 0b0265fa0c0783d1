//! Shared helpers for the geometry integration tests.
#![allow(dead_code)]

use geom::Mesh;
use geom::io::{ReadOptions, read_path};
use std::path::{Path, PathBuf};

pub fn shared_mesh(name: &str) -> PathBuf {
    let root = std::env::var_os("SURFMAP_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared"));
    let p = root.join("meshes").join(name);
    assert!(p.exists(), "shared mesh {} not found (set SURFMAP_SHARED)", p.display());
    p
}

pub fn load(name: &str) -> Mesh {
    read_path(&shared_mesh(name), &ReadOptions::default()).expect("read shared mesh").mesh
}

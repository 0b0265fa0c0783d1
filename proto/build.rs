//! Compiles `surfmap/v1/surfmap.proto` with protox (pure Rust; no system protoc) and keeps the
//! encoded descriptor set for gRPC reflection.

use prost::Message;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("cargo:rerun-if-changed=surfmap/v1/surfmap.proto");
    let fds = protox::compile(["surfmap/v1/surfmap.proto"], ["."])?;
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR")?);
    std::fs::write(out.join("surfmap_descriptor.bin"), fds.encode_to_vec())?;
    tonic_prost_build::configure().compile_fds(fds)?;
    Ok(())
}

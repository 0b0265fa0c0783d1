//! Times one canonical basis: `cargo run --release -p surfmap-geom --example basis_timing -- MESH [BASE]`.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: basis_timing MESH [BASE]");
        std::process::exit(2);
    };
    let base = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0u32);
    let m = match geom::io::read_path(std::path::Path::new(path), &Default::default()) {
        Ok(r) => r.mesh,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let t = std::time::Instant::now();
    match geom::homology::canonical_basis(&m, geom::VertexId(base), &Default::default()) {
        Ok(r) => println!("{} in {:.3} s: {}", path, t.elapsed().as_secs_f64(), r.word_text()),
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    }
}

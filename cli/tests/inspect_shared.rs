//! `surfmap inspect` on every mesh of `shared/meshes`, checked against its README table.

mod common;
use common::*;

#[test]
fn inspect_matches_readme_table_for_every_mesh() {
    let readme = std::fs::read_to_string(shared().join("meshes/README.md")).unwrap();
    let mut checked = 0;
    for line in readme.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | file | V | F | E | genus | boundary loops | ...
        if cells.len() < 8 || !(cells[1].ends_with(".off") || cells[1].ends_with(".obj")) {
            continue;
        }
        let Ok(v) = cells[2].parse::<u64>() else { continue };
        let (f, e, g, b): (u64, u64, i64, u64) = (
            cells[3].parse().unwrap(),
            cells[4].parse().unwrap(),
            cells[5].parse().unwrap(),
            cells[6].parse().unwrap(),
        );
        let path = mesh(cells[1]);
        let out = surfmap(&["inspect", path.to_str().unwrap()]);
        let j = stdout_json(&out);
        assert_eq!(j["vertices"], v, "{}", cells[1]);
        assert_eq!(j["faces"], f, "{}", cells[1]);
        assert_eq!(j["edges"], e, "{}", cells[1]);
        assert_eq!(j["genus"], g, "{}", cells[1]);
        assert_eq!(j["boundary_loops"], b, "{}", cells[1]);
        assert_eq!(j["components"], 1, "{}", cells[1]);
        assert_eq!(j["manifold"], true);
        assert_eq!(j["orientable"], true);
        // Euler characteristic agrees with the counts.
        assert_eq!(j["euler_characteristic"], v as i64 - e as i64 + f as i64);
        checked += 1;
    }
    assert!(checked >= 40, "only {checked} README rows checked");
}

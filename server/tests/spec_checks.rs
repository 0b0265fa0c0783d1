//! What a method cannot run is refused at submission (4xx, nothing queued), not after the
//! work: options that contradict each other, meshes the method does not take.

mod common;
use axum::body::Body;
use axum::http::StatusCode;
use common::*;
use serde_json::{Value, json};

async fn upload_spheres(t: &T, n: usize) -> Vec<Value> {
    let s = geom::mesh::shapes::icosphere(3);
    let mut ids = Vec::new();
    for k in 0..n {
        let f = 1.0 + 0.2 * k as f64;
        let m = s.with_positions(s.positions().iter().map(|p| geom::mesh::P3::new(p.x * f, p.y, p.z)).collect());
        let (_, a) = json_call(t, "POST", "/v1/meshes", geom::io::write(&m.unwrap(), geom::io::Format::Off)).await;
        ids.push(a["id"].clone());
    }
    ids
}

#[tokio::test]
async fn contradicting_quad_options_are_refused_before_queueing() {
    let t = setup().await;
    let ids = upload_spheres(&t, 2).await;
    let anchors = json!([[0, 0], [1, 1], [2, 2], [3, 3]]);
    let spec = json!({"method": "quad", "anchors": anchors,
        "options": {"adaptive_epsilon": 0.01, "morph": {"frames": 3, "domain": "wavelet"}}});
    let (st, e) = json_call(&t, "POST", "/v1/jobs", json!({"meshes": ids, "spec": spec}).to_string()).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("option_out_of_range")), "{e}");
    assert!(e["message"].as_str().unwrap().contains("adaptive_epsilon"), "{e}");
    // The wrong number of meshes for the method: 400 before anything runs.
    let one = json!({"meshes": [ids[0]], "spec": {"method": "voronoi", "anchors": [[0, 0], [1, 1], [2, 2]]}});
    let (st, e) = json_call(&t, "POST", "/v1/jobs", one.to_string()).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::BAD_REQUEST, Some("invalid_spec")), "{e}");
    let (_, page) = json_call(&t, "GET", "/v1/jobs", Body::empty()).await;
    assert_eq!(page["jobs"], json!([]), "nothing was queued");
}

/// Feature curves whose vertex lists no mesh of these summaries can hold: refused at
/// submission, not when the job runs.
#[tokio::test]
async fn feature_curves_out_of_range_or_repeating_are_refused_before_queueing() {
    let t = setup().await;
    let ids = upload_spheres(&t, 2).await;
    for (source, target, what) in [
        (json!([0, 99999]), json!([0, 1]), "out of range"),
        (json!([0]), json!([0, 1]), "at least 2"),
        (json!([0, 1, 0, 2]), json!([0, 1, 2, 3]), "repeats vertex 0"),
    ] {
        let spec =
            json!({"method": "homology", "anchors": [[5, 5]], "features": [{"source": source, "target": target}]});
        let body = json!({"source": ids[0], "target": ids[1], "spec": spec}).to_string();
        let (st, e) = json_call(&t, "POST", "/v1/jobs", body).await;
        assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("invalid_features")), "{e}");
        assert!(e["message"].as_str().unwrap().contains(what), "{what}: {e}");
    }
    // A closed curve (first vertex repeated last) passes these checks.
    let spec = json!({"method": "homology", "anchors": [[5, 5]], "features": [{"source": [0, 1, 2, 0], "target": [0, 1, 2, 0]}]});
    let body = json!({"source": ids[0], "target": ids[1], "spec": spec}).to_string();
    let (_, e) = json_call(&t, "POST", "/v1/jobs", body).await;
    assert_ne!(e["code"].as_str(), Some("invalid_features"), "{e}");
    let (_, page) = json_call(&t, "GET", "/v1/jobs", Body::empty()).await;
    assert!(page["jobs"].as_array().unwrap().len() <= 1, "only the closed curve's job may be queued");
}

/// A `transfer` of an attribute the source does not have: refused at submission (the source's
/// summary records its attributes), not after the map is built.
#[tokio::test]
async fn a_transfer_of_a_missing_attribute_is_refused_before_queueing() {
    let t = setup().await;
    let ids = upload_spheres(&t, 2).await;
    let (_, m) = json_call(&t, "GET", "/v1/jobs", Body::empty()).await;
    assert_eq!(m["jobs"], json!([]));
    for (transfer, missing) in [(json!(["TEXCOORD_0"]), "TEXCOORD_0"), (json!(["COLOR_0"]), "COLOR_0")] {
        let spec = json!({"method": "voronoi", "anchors": [[0, 0], [5, 5], [9, 9]], "options": {"transfer": transfer}});
        let body = json!({"source": ids[0], "target": ids[1], "spec": spec}).to_string();
        let (st, e) = json_call(&t, "POST", "/v1/jobs", body).await;
        assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("invalid_argument")), "{e}");
        let msg = e["message"].as_str().unwrap();
        assert!(msg.contains(missing) && msg.contains("no attributes"), "{e}");
    }
    let (_, page) = json_call(&t, "GET", "/v1/jobs", Body::empty()).await;
    assert_eq!(page["jobs"], json!([]), "nothing was queued");
}

/// A spec without `method` is an `auto` job: queued as such, and the chosen method's checks
/// apply at submission (here anchors inside the meshes).
#[tokio::test]
async fn a_spec_without_method_is_queued_as_auto_and_checked_as_the_method_it_picks() {
    let t = setup().await;
    let ids = upload_spheres(&t, 2).await;
    let spec = json!({"anchors": [[0, 0], [5, 5], [9, 9]], "options": {"metric_samples": 1000}});
    let (st, job) = json_call(&t, "POST", "/v1/jobs", json!({"meshes": ids, "spec": spec}).to_string()).await;
    assert!(st.is_success(), "{st} {job}");
    assert_eq!(job["method"], "auto", "{job}");
    let spec = json!({"method": "auto", "anchors": [[0, 0], [5, 5], [9, 9]], "options": {"smoothing": {}}});
    let (st, e) = json_call(&t, "POST", "/v1/jobs", json!({"meshes": ids, "spec": spec}).to_string()).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::BAD_REQUEST, Some("invalid_spec")), "{e}");
    let spec = json!({"anchors": [[0, 0], [5, 5], [9, 99999]]});
    let (st, e) = json_call(&t, "POST", "/v1/jobs", json!({"meshes": ids, "spec": spec}).to_string()).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("invalid_anchors")), "{e}");
}

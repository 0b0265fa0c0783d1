//! The dashboard's routes and the mesh routes its viewer reads, called on the router: pages
//! and embedded assets, the page's auth mode with and without tokens, a page request with a
//! wrong token refused, JSON 404s for unknown assets, and meshes only for their owner.

mod common;

use axum::body::Body;
use axum::http::{Request, StatusCode};
use common::{call, json_call, setup, setup_with};

fn get(uri: &str, auth: Option<&str>) -> Request<Body> {
    let mut r = Request::get(uri);
    if let Some(a) = auth {
        r = r.header("authorization", a);
    }
    r.body(Body::empty()).unwrap()
}

#[tokio::test]
async fn pages_assets_and_auth_modes() {
    let open = setup().await;
    let (st, h, body) = call(&open, get("/ui/", None)).await;
    let html = String::from_utf8(body).unwrap();
    assert_eq!((st, h["content-type"].to_str().unwrap()), (StatusCode::OK, "text/html; charset=utf-8"));
    assert!(html.contains(r#"<meta name="surfmap-auth" content="none">"#), "{html}");
    assert!(html.contains("/ui/assets/jobs.js"));
    let (st, h, _) = call(&open, get("/ui", None)).await;
    assert_eq!((st, h["location"].to_str().unwrap()), (StatusCode::PERMANENT_REDIRECT, "/ui/"));
    let (st, _, body) = call(&open, get("/ui/jobs/anything", None)).await;
    assert!(st == StatusCode::OK && String::from_utf8(body).unwrap().contains("/ui/assets/job.js"));
    for (path, ct) in [
        ("/ui/assets/app.css", "text/css; charset=utf-8"),
        ("/ui/assets/viewer.js", "text/javascript; charset=utf-8"),
        ("/ui/assets/vendor/three/three.module.js", "text/javascript; charset=utf-8"),
        ("/ui/assets/vendor/three/LICENSE", "text/plain; charset=utf-8"),
    ] {
        let (st, h, body) = call(&open, get(path, None)).await;
        assert_eq!((st, h["content-type"].to_str().unwrap()), (StatusCode::OK, ct), "{path}");
        assert!(!body.is_empty());
    }
    for path in ["/ui/assets/nope.js", "/ui/assets/../Cargo.toml", "/ui/assets/vendor/three/"] {
        let (st, v) = json_call(&open, "GET", path, Body::empty()).await;
        assert_eq!((st, v["code"].as_str()), (StatusCode::NOT_FOUND, Some("route_not_found")), "{path}");
    }

    let tenants = setup_with(&["alpha".into(), "beta".into()]).await;
    let mode = |body: Vec<u8>| {
        let html = String::from_utf8(body).unwrap();
        html.split(r#"name="surfmap-auth" content=""#).nth(1).and_then(|s| s.split('"').next()).unwrap().to_string()
    };
    assert_eq!(mode(call(&tenants, get("/ui/", None)).await.2), "token");
    assert_eq!(mode(call(&tenants, get("/ui/", Some("Bearer beta"))).await.2), "forwarded");
    assert_eq!(mode(call(&tenants, get("/ui/jobs/x", Some("bearer alpha"))).await.2), "forwarded");
    let (st, _, body) = call(&tenants, get("/ui/", Some("Bearer gamma"))).await;
    let v: serde_json::Value = serde_json::from_slice(&body).unwrap();
    assert_eq!((st, v["code"].as_str()), (StatusCode::UNAUTHORIZED, Some("unauthorized")));
    // Assets hold no data: served without a token.
    assert_eq!(call(&tenants, get("/ui/assets/jobs.js", None)).await.0, StatusCode::OK);
}

#[tokio::test]
async fn meshes_are_read_back_by_their_owner_only() {
    let t = setup_with(&["alpha".into(), "beta".into()]).await;
    let s = geom::mesh::shapes::icosphere(2);
    let bytes = geom::io::write(&s, geom::io::Format::Obj);
    let req = Request::post("/v1/meshes").header("authorization", "Bearer alpha").body(Body::from(bytes)).unwrap();
    let (st, _, b) = call(&t, req).await;
    assert_eq!(st, StatusCode::CREATED);
    let id = serde_json::from_slice::<serde_json::Value>(&b).unwrap()["id"].as_str().unwrap().to_string();
    let (st, _, b) = call(&t, get(&format!("/v1/meshes/{id}"), Some("Bearer alpha"))).await;
    let v: serde_json::Value = serde_json::from_slice(&b).unwrap();
    assert_eq!(
        (st, v["id"].as_str(), v["summary"]["vertices"].as_u64()),
        (StatusCode::OK, Some(id.as_str()), Some(162))
    );
    let (st, h, glb) = call(&t, get(&format!("/v1/meshes/{id}/glb"), Some("Bearer alpha"))).await;
    assert_eq!((st, h["content-type"].to_str().unwrap()), (StatusCode::OK, "model/gltf-binary"));
    assert_eq!(&glb[..4], b"glTF");
    let back = geom::io::read(&glb, &Default::default()).unwrap().mesh;
    assert_eq!((back.n_vertices(), back.n_faces()), (s.n_vertices(), s.n_faces()));
    for path in [format!("/v1/meshes/{id}"), format!("/v1/meshes/{id}/glb")] {
        let (st, _, b) = call(&t, get(&path, Some("Bearer beta"))).await;
        let v: serde_json::Value = serde_json::from_slice(&b).unwrap();
        assert_eq!((st, v["code"].as_str()), (StatusCode::NOT_FOUND, Some("mesh_not_found")), "{path}");
        assert_eq!(call(&t, get(&path, None)).await.0, StatusCode::UNAUTHORIZED);
    }
    let (st, _, b) = call(&t, get("/v1/meshes/..%2Fetc/glb", Some("Bearer alpha"))).await;
    let v: serde_json::Value = serde_json::from_slice(&b).unwrap();
    assert_eq!((st, v["code"].as_str()), (StatusCode::BAD_REQUEST, Some("invalid_mesh_id")));
}

//! Content-addressed blobs (uploaded meshes, job artifacts) on an object store (the
//! `object_store` crate), key `ab/cdef…` by sha256: a local directory (`file:///path`, the
//! default, under `--data-dir`) or an S3-compatible bucket (`s3://bucket/prefix`, configured by
//! the standard `AWS_*` variables). Server and workers on different machines share a bucket,
//! not a filesystem. Writes are whole-object PUTs (the local store writes a temporary file and
//! renames it), so a reader never sees a partial blob, and two writers of the same content
//! write the same bytes.

use object_store::path::Path as ObjectPath;
use object_store::{ObjectStore, ObjectStoreExt, PutPayload};
use sha2::{Digest, Sha256};
use std::path::Path;
use std::sync::Arc;

/// The blob store shared by the server and every worker.
#[derive(Debug, Clone)]
pub struct BlobStore {
    store: Arc<dyn ObjectStore>,
    /// Where the blobs live, for logs: `file:///…` or `s3://bucket/prefix`.
    url: String,
}

/// The sha256 of `bytes`, as lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex::encode(Sha256::digest(bytes))
}

fn io(e: object_store::Error) -> std::io::Error {
    std::io::Error::other(e)
}

impl BlobStore {
    /// Opens (creating) the blob directory `blobs/` under `data_dir`.
    ///
    /// # Errors
    /// When the directory cannot be created.
    pub fn open(data_dir: &Path) -> std::io::Result<BlobStore> {
        let root = data_dir.join("blobs");
        std::fs::create_dir_all(&root)?;
        let root = std::fs::canonicalize(root)?;
        let store = object_store::local::LocalFileSystem::new_with_prefix(&root).map_err(io)?;
        Ok(BlobStore { store: Arc::new(store), url: format!("file://{}", root.display()) })
    }

    /// The store a `--blob-url` names: `file:///path` (a directory) or `s3://bucket[/prefix]`
    /// (endpoint, credentials and region from `AWS_ENDPOINT_URL`, `AWS_ACCESS_KEY_ID`,
    /// `AWS_SECRET_ACCESS_KEY`, `AWS_REGION`, `AWS_ALLOW_HTTP`); `None` means the
    /// `blobs/` directory under `data_dir`.
    ///
    /// # Errors
    /// An unsupported scheme, a bad URL, or a store that cannot be set up.
    pub fn from_url(url: Option<&str>, data_dir: &Path) -> std::io::Result<BlobStore> {
        let Some(url) = url.filter(|u| !u.is_empty()) else { return Self::open(data_dir) };
        let bad = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
        if let Some(path) = url.strip_prefix("file://") {
            std::fs::create_dir_all(path)?;
            let store = object_store::local::LocalFileSystem::new_with_prefix(path).map_err(io)?;
            return Ok(BlobStore { store: Arc::new(store), url: url.to_string() });
        }
        let Some(rest) = url.strip_prefix("s3://") else {
            return Err(bad(format!("blob URL {url:?}: use file:///path or s3://bucket/prefix")));
        };
        let (bucket, prefix) = rest.split_once('/').unwrap_or((rest, ""));
        if bucket.is_empty() {
            return Err(bad(format!("blob URL {url:?} names no bucket")));
        }
        let mut b = object_store::aws::AmazonS3Builder::from_env().with_bucket_name(bucket);
        // The standard variable of the AWS SDKs; object_store's own is AWS_ENDPOINT.
        if let Ok(e) = std::env::var("AWS_ENDPOINT_URL") {
            b = b.with_endpoint(e);
        }
        if std::env::var("AWS_REGION").is_err() && std::env::var("AWS_DEFAULT_REGION").is_err() {
            b = b.with_region("us-east-1");
        }
        let s3: Arc<dyn ObjectStore> = Arc::new(b.build().map_err(io)?);
        let prefix = prefix.trim_matches('/');
        let store: Arc<dyn ObjectStore> =
            if prefix.is_empty() { s3 } else { Arc::new(object_store::prefix::PrefixStore::new(s3, prefix)) };
        Ok(BlobStore { store, url: url.to_string() })
    }

    /// Where the blobs live (`file:///…` or `s3://…`).
    pub fn url(&self) -> &str {
        &self.url
    }

    /// The sha256 key of `bytes`.
    pub fn key(bytes: &[u8]) -> String {
        sha256_hex(bytes)
    }

    /// A valid key is 64 lowercase hex digits; anything else (`../x`) is refused.
    pub fn valid_key(key: &str) -> bool {
        key.len() == 64 && key.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
    }

    fn path(key: &str) -> Option<ObjectPath> {
        Self::valid_key(key).then(|| ObjectPath::from(format!("{}/{}", &key[..2], &key[2..])))
    }

    /// Stores `bytes`; returns their key. Idempotent.
    ///
    /// # Errors
    /// Store failures.
    pub async fn put(&self, bytes: &[u8]) -> std::io::Result<String> {
        let key = Self::key(bytes);
        let path = Self::path(&key).ok_or_else(|| std::io::Error::other("bad key"))?;
        if self.store.head(&path).await.is_ok() {
            return Ok(key);
        }
        self.store.put(&path, PutPayload::from(bytes.to_vec())).await.map_err(io)?;
        Ok(key)
    }

    /// The bytes under `key`, or `None` when absent or the key is invalid.
    ///
    /// # Errors
    /// Store failures other than not-found.
    pub async fn get(&self, key: &str) -> std::io::Result<Option<Vec<u8>>> {
        let Some(path) = Self::path(key) else { return Ok(None) };
        match self.store.get(&path).await {
            Ok(r) => Ok(Some(r.bytes().await.map_err(io)?.to_vec())),
            Err(object_store::Error::NotFound { .. }) => Ok(None),
            Err(e) => Err(io(e)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn put_get_roundtrip_and_bad_keys() {
        let dir = tempfile::tempdir().unwrap();
        let b = BlobStore::open(dir.path()).unwrap();
        let k = b.put(b"hello").await.unwrap();
        assert_eq!(k, "2cf24dba5fb0a30e26e83b2ac5b9e29e1b161e5c1fa7425e73043362938b9824");
        assert_eq!(b.put(b"hello").await.unwrap(), k);
        assert_eq!(b.get(&k).await.unwrap().as_deref(), Some(&b"hello"[..]));
        assert!(b.get("../../etc/passwd").await.unwrap().is_none());
        assert!(!BlobStore::valid_key(&"A".repeat(64)));
        assert!(b.get(&"0".repeat(64)).await.unwrap().is_none());
        assert!(dir.path().join("blobs").join(&k[..2]).join(&k[2..]).exists(), "the directory layout is kept");
    }

    #[test]
    fn blob_urls() {
        let dir = tempfile::tempdir().unwrap();
        assert!(BlobStore::from_url(None, dir.path()).unwrap().url().starts_with("file://"));
        assert!(BlobStore::from_url(Some("ftp://x"), dir.path()).is_err());
        assert!(BlobStore::from_url(Some("s3://"), dir.path()).is_err());
        let s3 = BlobStore::from_url(Some("s3://bucket/some/prefix"), dir.path()).unwrap();
        assert_eq!(s3.url(), "s3://bucket/some/prefix");
    }
}

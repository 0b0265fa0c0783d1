//! Content-addressed blobs (uploaded meshes, job artifacts) in a directory: `ab/cdef…` by
//! sha256. Writes go to a temporary file and are renamed into place, so a reader never sees a
//! partial blob and two writers of the same content agree. At scale the same keys map onto an
//! object store bucket (see ARCHITECTURE.md).

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// A blob directory shared by the server and every worker.
#[derive(Debug, Clone)]
pub struct BlobStore {
    root: PathBuf,
}

/// The sha256 of `bytes`, as lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex::encode(Sha256::digest(bytes))
}

impl BlobStore {
    /// Opens (creating) the blob directory under `data_dir`.
    ///
    /// # Errors
    /// When the directory cannot be created.
    pub fn open(data_dir: &Path) -> std::io::Result<BlobStore> {
        let root = data_dir.join("blobs");
        std::fs::create_dir_all(&root)?;
        Ok(BlobStore { root })
    }

    /// The sha256 key of `bytes`.
    pub fn key(bytes: &[u8]) -> String {
        sha256_hex(bytes)
    }

    /// A valid key is 64 lowercase hex digits; anything else (`../x`) is refused.
    pub fn valid_key(key: &str) -> bool {
        key.len() == 64 && key.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
    }

    fn path(&self, key: &str) -> Option<PathBuf> {
        Self::valid_key(key).then(|| self.root.join(&key[..2]).join(&key[2..]))
    }

    /// Stores `bytes`; returns their key. Idempotent.
    ///
    /// # Errors
    /// I/O failures.
    pub async fn put(&self, bytes: &[u8]) -> std::io::Result<String> {
        let key = Self::key(bytes);
        let path = self.path(&key).ok_or_else(|| std::io::Error::other("bad key"))?;
        if tokio::fs::try_exists(&path).await.unwrap_or(false) {
            return Ok(key);
        }
        let dir = path.parent().ok_or_else(|| std::io::Error::other("no parent"))?;
        tokio::fs::create_dir_all(dir).await?;
        let tmp = dir.join(format!(".{}.{}.tmp", &key[2..], uuid::Uuid::new_v4().simple()));
        tokio::fs::write(&tmp, bytes).await?;
        tokio::fs::rename(&tmp, &path).await?;
        Ok(key)
    }

    /// The bytes under `key`, or `None` when absent or the key is invalid.
    ///
    /// # Errors
    /// I/O failures other than not-found.
    pub async fn get(&self, key: &str) -> std::io::Result<Option<Vec<u8>>> {
        let Some(path) = self.path(key) else { return Ok(None) };
        match tokio::fs::read(&path).await {
            Ok(b) => Ok(Some(b)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e),
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
    }
}

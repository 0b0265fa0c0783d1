//! Bearer tokens. Without configured tokens every client is the anonymous owner `""`; with
//! tokens, a request must present one, and its owner is a hash of the token (never the token
//! itself), so clients see only their own jobs and meshes.

use crate::error::ApiError;
use sha2::{Digest, Sha256};

/// The configured tokens, as owner hashes.
#[derive(Debug, Clone, Default)]
pub struct Auth {
    owners: Vec<(Vec<u8>, String)>,
    /// Hash of the operators' token for `/metrics`, if one is configured.
    metrics: Option<Vec<u8>>,
}

impl Auth {
    pub fn new(tokens: &[String]) -> Auth {
        let owners = tokens
            .iter()
            .filter(|t| !t.is_empty())
            .map(|t| {
                let h = Sha256::digest(t.as_bytes());
                (h.to_vec(), hex::encode(&h[..12]))
            })
            .collect();
        Auth { owners, metrics: None }
    }

    /// Requires `token` for `/metrics` (`--metrics-token`); empty or `None` leaves it unset.
    pub fn with_metrics_token(mut self, token: Option<&str>) -> Auth {
        self.metrics = token.filter(|t| !t.is_empty()).map(|t| Sha256::digest(t.as_bytes()).to_vec());
        self
    }

    /// May this request read `/metrics`? With a metrics token, only with that token; else,
    /// when API tokens are configured, never (the figures span every tenant); else always.
    ///
    /// # Errors
    /// 401 when the request may not.
    pub fn metrics_allowed(&self, authorization: Option<&str>) -> Result<(), ApiError> {
        let presented = authorization.and_then(bearer_token);
        match (&self.metrics, presented) {
            (Some(k), Some(t)) if k[..] == Sha256::digest(t.as_bytes())[..] => Ok(()),
            (Some(_), _) => Err(ApiError::unauthorized()),
            (None, _) if self.enabled() => Err(ApiError::unauthorized()),
            (None, _) => Ok(()),
        }
    }

    pub fn enabled(&self) -> bool {
        !self.owners.is_empty()
    }

    /// The owner for an `Authorization` header value.
    ///
    /// # Errors
    /// 401 when tokens are configured and the header is missing or unknown.
    pub fn owner(&self, authorization: Option<&str>) -> Result<String, ApiError> {
        if !self.enabled() {
            return Ok(String::new());
        }
        let token = authorization.and_then(bearer_token).ok_or_else(ApiError::unauthorized)?;
        let h = Sha256::digest(token.as_bytes());
        // Compare hashes, not tokens: no early exit on a prefix of a secret.
        self.owners.iter().find(|(k, _)| k[..] == h[..]).map(|(_, o)| o.clone()).ok_or_else(ApiError::unauthorized)
    }
}

/// The token of an `Authorization: Bearer TOKEN` value; the scheme name is case-insensitive
/// (RFC 9110 §11.1), so `bearer T` and `BEARER T` present `T` too.
pub fn bearer_token(authorization: &str) -> Option<&str> {
    let (scheme, token) = authorization.trim_start().split_once([' ', '\t'])?;
    let token = token.trim();
    (scheme.eq_ignore_ascii_case("bearer") && !token.is_empty()).then_some(token)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_map_to_distinct_owners() {
        assert_eq!(Auth::new(&[]).owner(None).unwrap(), "");
        let a = Auth::new(&["alpha".into(), "beta".into()]);
        let (x, y) = (a.owner(Some("Bearer alpha")).unwrap(), a.owner(Some("Bearer beta")).unwrap());
        assert!(!x.is_empty() && x != y);
        assert_eq!(a.owner(Some("Bearer gamma")).unwrap_err().code, "unauthorized");
        assert_eq!(a.owner(None).unwrap_err().code, "unauthorized");
        // The scheme name is case-insensitive; the token is not.
        for h in ["bearer alpha", "BEARER alpha", "Bearer   alpha ", "bEaReR\talpha"] {
            assert_eq!(a.owner(Some(h)).unwrap(), x, "{h:?}");
        }
        for h in ["Bearer ALPHA", "Basic alpha", "Bearer", "Bearer ", "Beareralpha", "alpha"] {
            assert_eq!(a.owner(Some(h)).unwrap_err().code, "unauthorized", "{h:?}");
        }
    }

    #[test]
    fn metrics_need_the_metrics_token_when_tokens_are_configured() {
        assert!(Auth::new(&[]).metrics_allowed(None).is_ok());
        let tenants = Auth::new(&["alpha".into()]);
        assert!(tenants.metrics_allowed(Some("Bearer alpha")).is_err(), "a tenant sees no global figures");
        let ops = Auth::new(&["alpha".into()]).with_metrics_token(Some("ops"));
        assert!(ops.metrics_allowed(Some("Bearer ops")).is_ok());
        assert!(ops.metrics_allowed(Some("Bearer alpha")).is_err());
        assert!(ops.metrics_allowed(None).is_err());
        let open = Auth::new(&[]).with_metrics_token(Some("ops"));
        assert!(open.metrics_allowed(None).is_err() && open.metrics_allowed(Some("Bearer ops")).is_ok());
    }
}

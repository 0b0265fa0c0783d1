//! geodesic

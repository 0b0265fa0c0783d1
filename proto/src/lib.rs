//! Generated types, client and server of `surfmap.v1`, and the descriptor set that gRPC
//! reflection serves.

#![allow(clippy::all, clippy::pedantic, missing_docs)]

/// `package surfmap.v1`.
pub mod v1 {
    tonic::include_proto!("surfmap.v1");
}

/// The encoded `FileDescriptorSet` of the contract.
pub const FILE_DESCRIPTOR_SET: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/surfmap_descriptor.bin"));

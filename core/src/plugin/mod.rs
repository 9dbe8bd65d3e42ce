//! Oracle plugins: the stable C ABI ([`abi`]), the helpers a Rust plugin uses to export an
//! [`Oracle`](crate::oracle::Oracle) through it ([`export`],
//! [`export_oracle_plugin!`](crate::export_oracle_plugin)), and the host-side loader ([`host`])
//! that turns a shared library back into an `Oracle`.

// A C ABI is raw pointers and foreign calls: the two sides of the boundary are where the plugin
// code is unsafe, each block with the invariant that makes it sound.
pub mod abi;
#[allow(
    unsafe_code,
    reason = "the exported entry points dereference the host's pointers"
)]
pub mod export;
#[allow(unsafe_code, reason = "the loader calls into a foreign library")]
pub mod host;

pub use export::PluginOracle;
pub use host::{DynOracle, HitQuery, PluginError, PluginInfo, PluginLibrary, PluginProblem};

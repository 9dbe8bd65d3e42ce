//! Oracle plugins: the stable C ABI ([`abi`]), the helpers a Rust plugin uses to export an
//! [`Oracle`](crate::oracle::Oracle) through it ([`export`], [`export_oracle_plugin!`]), and the
//! host-side loader ([`host`]) that turns a shared library back into an `Oracle`.

pub mod abi;
pub mod export;
pub mod host;

pub use export::PluginOracle;
pub use host::{DynOracle, PluginError, PluginInfo, PluginLibrary, PluginProblem};

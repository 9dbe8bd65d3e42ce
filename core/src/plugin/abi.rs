//! The stable C ABI of delamesh oracle plugins, version 1.
//!
//! This file is the single source of truth: `include/delamesh_plugin.h` is generated from it with
//! cbindgen (a test fails when the header is stale). Only plain C types appear here — no Rust
//! enums, no references, no `bool` — so that a plugin written in C, C++ or Rust can fill the table
//! and a host can read it without undefined behaviour even when the plugin is wrong.
//!
//! A plugin is a shared library exporting one symbol, `delamesh_plugin_v1`, of type
//! [`DmPluginEntryV1`]. It returns a pointer to a static [`DmPluginV1`] table. See `PLUGINS.md` for
//! the contract (thread safety, ownership, units, error reporting, versioning).

use std::ffi::{c_char, c_void};

/// The ABI version this header describes. A host refuses a table whose `abi_version` differs.
pub const DM_ABI_VERSION: u32 = 1;

/// The call succeeded; outputs are written.
pub const DM_OK: i32 = 0;
/// The query failed; `last_error` explains why. Outputs are unspecified.
pub const DM_ERROR: i32 = 1;
/// The caller's buffer is too small: the required length was written to `*len` and nothing else.
/// The caller grows its buffer to at least that length and calls again.
pub const DM_BUFFER_TOO_SMALL: i32 = 2;

/// A point or a vector, in the units of the domain (the same units as the input geometry).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DmVec3 {
    /// The x coordinate.
    pub x: f64,
    /// The y coordinate.
    pub y: f64,
    /// The z coordinate.
    pub z: f64,
}

/// An axis-aligned box containing the whole domain.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DmAabb {
    /// The corner with the smallest coordinates.
    pub min: DmVec3,
    /// The corner with the largest coordinates.
    pub max: DmVec3,
}

/// One crossing of a segment or a ray with a boundary surface patch.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DmSurfaceHit {
    /// Where the query crosses the surface.
    pub point: DmVec3,
    /// Parameter along the query: `a + t (b - a)` for a segment (0 ≤ t ≤ 1), `origin + t dir` for
    /// a ray (t ≥ 0).
    pub t: f64,
    /// Surface patch id, numbered from 1.
    pub patch: u32,
}

/// A point on a boundary surface and the patch it lies on.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DmSurfacePoint {
    /// The point on the surface.
    pub point: DmVec3,
    /// Surface patch id, numbered from 1.
    pub patch: u32,
}

/// A 1D feature curve: `len` consecutive points starting at index `first` of the points buffer
/// passed alongside.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DmFeatureCurve {
    /// Curve id, numbered from 1.
    pub id: u32,
    /// Non-zero when the last point joins the first.
    pub closed: u32,
    /// Index of the curve's first point in the points buffer.
    pub first: usize,
    /// Number of points of the curve.
    pub len: usize,
}

// Every function type is an `Option` because a C table may hold NULL: the host checks the required
// ones once, at load time, instead of trusting the plugin.

/// Builds an oracle from a configuration string (UTF-8, NUL-terminated, possibly empty; its syntax
/// is the plugin's). Returns an opaque handle, or NULL after writing a NUL-terminated message of at
/// most `error_cap` bytes (truncated if needed) into `error`.
pub type DmCreateFn = Option<
    unsafe extern "C" fn(
        config: *const c_char,
        error: *mut c_char,
        error_cap: usize,
    ) -> *mut c_void,
>;

/// Releases a handle returned by `create`. Called exactly once per handle, when no query on it is
/// running.
pub type DmDestroyFn = Option<unsafe extern "C" fn(oracle: *mut c_void)>;

/// Copies the message of the last failed call made on the calling thread into `buf` (at most
/// `cap` bytes, NUL-terminated, truncated if needed) and returns the full message length in bytes
/// without the NUL.
pub type DmLastErrorFn =
    Option<unsafe extern "C" fn(oracle: *const c_void, buf: *mut c_char, cap: usize) -> usize>;

/// Writes a box containing the whole domain into `out`.
pub type DmBoundingBoxFn =
    Option<unsafe extern "C" fn(oracle: *const c_void, out: *mut DmAabb) -> i32>;

/// Batch point location: writes into `out[i]` the subdomain containing `points[i]` for every
/// `i < n`, 0 meaning outside. Batched because it is the cheapest and most frequent query.
pub type DmSubdomainsFn = Option<
    unsafe extern "C" fn(
        oracle: *const c_void,
        points: *const DmVec3,
        n: usize,
        out: *mut u32,
    ) -> i32,
>;

/// Every crossing of the closed segment `[a, b]` (or of the ray `a + t b`, t ≥ 0) with the
/// boundary surfaces, sorted by `t`, written into `out` (capacity `cap`) with the count in `*len`.
pub type DmHitsFn = Option<
    unsafe extern "C" fn(
        oracle: *const c_void,
        a: DmVec3,
        b: DmVec3,
        out: *mut DmSurfaceHit,
        cap: usize,
        len: *mut usize,
    ) -> i32,
>;

/// Points on the boundary, several on every connected component, written into `out` (capacity
/// `cap`) with the count in `*len`.
pub type DmInitialPointsFn = Option<
    unsafe extern "C" fn(
        oracle: *const c_void,
        out: *mut DmSurfacePoint,
        cap: usize,
        len: *mut usize,
    ) -> i32,
>;

/// Corners (0D features) the mesh must contain as vertices, written into `out` (capacity `cap`)
/// with the count in `*len`.
pub type DmCornersFn = Option<
    unsafe extern "C" fn(
        oracle: *const c_void,
        out: *mut DmVec3,
        cap: usize,
        len: *mut usize,
    ) -> i32,
>;

/// 1D feature curves: the curves into `curves` (capacity `curves_cap`, count in `*curves_len`) and
/// their points, concatenated, into `points` (capacity `points_cap`, count in `*points_len`).
/// `DM_BUFFER_TOO_SMALL` when either buffer is too small; both counts are written then.
pub type DmFeatureCurvesFn = Option<
    unsafe extern "C" fn(
        oracle: *const c_void,
        curves: *mut DmFeatureCurve,
        curves_cap: usize,
        curves_len: *mut usize,
        points: *mut DmVec3,
        points_cap: usize,
        points_len: *mut usize,
    ) -> i32,
>;

/// The function table of a version-1 plugin. Every function but `feature_curves` and `corners`
/// is required; those two may be NULL for smooth domains without 1D or 0D features.
#[repr(C)]
pub struct DmPluginV1 {
    /// Must be `DM_ABI_VERSION`.
    pub abi_version: u32,
    /// `sizeof(DmPluginV1)` as the plugin was compiled: lets later minor versions append fields.
    pub struct_size: u32,
    /// Short plugin name (UTF-8, NUL-terminated, static), e.g. "polyhedral".
    pub name: *const c_char,
    /// What the plugin meshes, e.g. "surface-mesh", "implicit", "labelled-image".
    pub kind: *const c_char,
    /// The plugin's own version, e.g. "1.2.0".
    pub version: *const c_char,
    /// Creates an oracle from a configuration string: see [`DmCreateFn`].
    pub create: DmCreateFn,
    /// Frees an oracle made by `create`.
    pub destroy: DmDestroyFn,
    /// The message of the last failed call on this thread.
    pub last_error: DmLastErrorFn,
    /// A box around the whole domain.
    pub bounding_box: DmBoundingBoxFn,
    /// The subdomain of each point of a batch (0 outside).
    pub subdomains: DmSubdomainsFn,
    /// The crossings of a segment with the boundary, sorted by `t`.
    pub segment_hits: DmHitsFn,
    /// The crossings of a ray with the boundary, sorted by `t`.
    pub ray_hits: DmHitsFn,
    /// Points on the boundary, at least one per component, to start refinement.
    pub initial_points: DmInitialPointsFn,
    /// The 1D features as polylines; NULL when there are none.
    pub feature_curves: DmFeatureCurvesFn,
    /// The 0D features; NULL when there are none.
    pub corners: DmCornersFn,
}

/// Type of the one symbol a plugin exports, `delamesh_plugin_v1`. The table it returns must stay
/// valid until the library is unloaded.
pub type DmPluginEntryV1 = unsafe extern "C" fn() -> *const DmPluginV1;

/// Name of the entry point symbol.
pub const DM_ENTRY_SYMBOL: &str = "delamesh_plugin_v1";

impl From<glam::DVec3> for DmVec3 {
    fn from(p: glam::DVec3) -> Self {
        DmVec3 {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    }
}

impl From<DmVec3> for glam::DVec3 {
    fn from(p: DmVec3) -> Self {
        glam::DVec3::new(p.x, p.y, p.z)
    }
}

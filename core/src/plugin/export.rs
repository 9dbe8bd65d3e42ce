//! Plugin side: turns a Rust [`Oracle`] into the C table, so that a plugin crate only writes
//! `export_oracle_plugin!(MyOracle, name = "...", kind = "...")`.
//!
//! Every exported function runs the oracle under `catch_unwind`: a panic becomes `DM_ERROR` with
//! the panic message as the last error, and never unwinds into the host (which would abort it).

use super::abi::*;
use crate::oracle::{Oracle, SurfaceHit, SurfacePoint};
use std::any::Any;
use std::cell::RefCell;
use std::ffi::{CStr, c_char, c_void};
use std::panic::{AssertUnwindSafe, RefUnwindSafe, UnwindSafe, catch_unwind};

/// A Rust oracle that can be built from a plugin configuration string.
pub trait PluginOracle: Oracle + Sized + 'static {
    /// Parses `config` (the text after `--plugin-config`) and builds the oracle.
    fn from_config(config: &str) -> Result<Self, String>;
}

/// The static table of a plugin: the C table plus the `Sync` promise Rust needs for a `static`
/// holding raw pointers (they point to static strings and functions, never mutated).
#[repr(transparent)]
pub struct ExportedTable(DmPluginV1);

// SAFETY: the table is immutable and its pointers target `'static` NUL-terminated strings.
unsafe impl Sync for ExportedTable {}

impl ExportedTable {
    /// The table of `T`. `name`, `kind` and `version` must be NUL-terminated (the macro adds it).
    pub const fn new<T: PluginOracle>(
        name: &'static str,
        kind: &'static str,
        version: &'static str,
    ) -> Self {
        ExportedTable(DmPluginV1 {
            abi_version: DM_ABI_VERSION,
            struct_size: size_of::<DmPluginV1>() as u32,
            name: name.as_ptr().cast(),
            kind: kind.as_ptr().cast(),
            version: version.as_ptr().cast(),
            create: Some(create::<T>),
            destroy: Some(destroy::<T>),
            last_error: Some(last_error),
            bounding_box: Some(bounding_box::<T>),
            subdomains: Some(subdomains::<T>),
            segment_hits: Some(hits::<T, false>),
            ray_hits: Some(hits::<T, true>),
            initial_points: Some(list::<T, DmSurfacePoint>),
            feature_curves: Some(feature_curves::<T>),
            corners: Some(list::<T, DmVec3>),
        })
    }

    /// The pointer `delamesh_plugin_v1` returns: the table lives as long as the library.
    pub const fn as_ptr(&'static self) -> *const DmPluginV1 {
        &self.0
    }
}

/// Exports a [`PluginOracle`] as a delamesh plugin: defines the `delamesh_plugin_v1` entry point.
///
/// ```ignore
/// delamesh_core::export_oracle_plugin!(MyOracle, name = "my-oracle", kind = "implicit");
/// ```
///
/// Use it once per shared library: two crates exporting the entry point cannot be linked into
/// one binary (built-in plugins therefore export it only under their `cdylib` feature, built with
/// `cargo rustc --crate-type cdylib`).
#[macro_export]
macro_rules! export_oracle_plugin {
    ($oracle:ty, name = $name:literal, kind = $kind:literal) => {
        /// Entry point of this delamesh plugin (C ABI version 1).
        #[unsafe(no_mangle)]
        pub extern "C" fn delamesh_plugin_v1() -> *const $crate::plugin::abi::DmPluginV1 {
            static TABLE: $crate::plugin::export::ExportedTable =
                $crate::plugin::export::ExportedTable::new::<$oracle>(
                    concat!($name, "\0"),
                    concat!($kind, "\0"),
                    concat!(env!("CARGO_PKG_VERSION"), "\0"),
                );
            TABLE.as_ptr()
        }
    };
}

thread_local! {
    /// Message of the last failed call on this thread (the contract of `last_error`).
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
    /// Reused hit buffer, so hot segment queries do not allocate.
    static HITS: RefCell<Vec<SurfaceHit>> = const { RefCell::new(Vec::new()) };
}

fn panic_message(payload: &(dyn Any + Send)) -> String {
    let text = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic payload".to_string());
    format!("panicked: {text}")
}

/// Runs a query body, turning an `Err` or a panic into `DM_ERROR` + last error.
fn guarded(body: impl FnOnce() -> Result<i32, String> + UnwindSafe) -> i32 {
    let message = match catch_unwind(body) {
        Ok(Ok(status)) => return status,
        Ok(Err(message)) => message,
        Err(payload) => panic_message(payload.as_ref()),
    };
    LAST_ERROR.with(|e| *e.borrow_mut() = message);
    DM_ERROR
}

/// # Safety
/// `handle` must come from `create::<T>` and not be destroyed yet.
unsafe fn oracle<'a, T>(handle: *const c_void) -> Result<&'a T, String> {
    if handle.is_null() {
        return Err("null oracle handle".to_string());
    }
    // SAFETY: per the contract, `handle` is a live `Box<T>` from `create::<T>`.
    Ok(unsafe { &*handle.cast::<T>() })
}

/// Copies `text` into a caller buffer of `cap` bytes, truncated and NUL-terminated.
///
/// # Safety
/// `buf` must be valid for `cap` bytes, or null.
unsafe fn write_c_string(text: &str, buf: *mut c_char, cap: usize) -> usize {
    if !buf.is_null() && cap > 0 {
        let n = text.len().min(cap - 1);
        // SAFETY: `n + 1 <= cap` bytes of `buf` are writable.
        unsafe {
            std::ptr::copy_nonoverlapping(text.as_ptr().cast::<c_char>(), buf, n);
            *buf.add(n) = 0;
        }
    }
    text.len()
}

/// The capacity protocol: writes `items` into `out` if they fit, and their count into `*len`.
///
/// # Safety
/// `out` must be valid for `cap` writes and `len` for one.
unsafe fn fill<T: Copy>(
    items: impl ExactSizeIterator<Item = T>,
    out: *mut T,
    cap: usize,
    len: *mut usize,
) -> Result<i32, String> {
    if len.is_null() {
        return Err("null length pointer".to_string());
    }
    let n = items.len();
    // SAFETY: `len` is valid for one write.
    unsafe { *len = n };
    if n > cap {
        return Ok(DM_BUFFER_TOO_SMALL);
    }
    if n > 0 && out.is_null() {
        return Err("null output buffer".to_string());
    }
    for (i, item) in items.enumerate() {
        // SAFETY: `i < n <= cap`.
        unsafe { out.add(i).write(item) };
    }
    Ok(DM_OK)
}

unsafe extern "C" fn create<T: PluginOracle>(
    config: *const c_char,
    error: *mut c_char,
    error_cap: usize,
) -> *mut c_void {
    let built = catch_unwind(|| {
        let config = if config.is_null() {
            ""
        } else {
            // SAFETY: the host passes a NUL-terminated string.
            unsafe { CStr::from_ptr(config) }
                .to_str()
                .map_err(|_| "configuration is not UTF-8".to_string())?
        };
        T::from_config(config)
    });
    let message = match built {
        Ok(Ok(oracle)) => return Box::into_raw(Box::new(oracle)).cast(),
        Ok(Err(message)) => message,
        Err(payload) => panic_message(payload.as_ref()),
    };
    // SAFETY: the host passes a buffer of `error_cap` bytes.
    unsafe { write_c_string(&message, error, error_cap) };
    std::ptr::null_mut()
}

unsafe extern "C" fn destroy<T: PluginOracle>(handle: *mut c_void) {
    if !handle.is_null() {
        // A panicking `Drop` is swallowed: there is nobody left to report it to.
        let _ = catch_unwind(AssertUnwindSafe(|| {
            // SAFETY: `handle` is a live `Box<T>` from `create::<T>`, destroyed once.
            drop(unsafe { Box::from_raw(handle.cast::<T>()) })
        }));
    }
}

unsafe extern "C" fn last_error(_handle: *const c_void, buf: *mut c_char, cap: usize) -> usize {
    // SAFETY: the host passes a buffer of `cap` bytes.
    LAST_ERROR.with(|e| unsafe { write_c_string(&e.borrow(), buf, cap) })
}

unsafe extern "C" fn bounding_box<T: PluginOracle>(handle: *const c_void, out: *mut DmAabb) -> i32 {
    guarded(|| {
        // SAFETY: see `oracle`.
        let bbox = unsafe { oracle::<T>(handle) }?.bounding_box();
        if out.is_null() {
            return Err("null output pointer".to_string());
        }
        // SAFETY: `out` is valid for one write.
        unsafe {
            out.write(DmAabb {
                min: bbox.min.into(),
                max: bbox.max.into(),
            })
        };
        Ok(DM_OK)
    })
}

unsafe extern "C" fn subdomains<T: PluginOracle>(
    handle: *const c_void,
    points: *const DmVec3,
    n: usize,
    out: *mut u32,
) -> i32 {
    guarded(|| {
        // SAFETY: see `oracle`.
        let oracle = unsafe { oracle::<T>(handle) }?;
        if n == 0 {
            return Ok(DM_OK);
        }
        if points.is_null() || out.is_null() {
            return Err("null point or output buffer".to_string());
        }
        // SAFETY: the host passes `n` points and room for `n` labels.
        let (points, out) = unsafe {
            (
                std::slice::from_raw_parts(points, n),
                std::slice::from_raw_parts_mut(out, n),
            )
        };
        for (p, label) in points.iter().zip(out) {
            *label = oracle.subdomain((*p).into()).0;
        }
        Ok(DM_OK)
    })
}

/// `segment_hits` (`RAY` false: `a` and `b` are the segment's ends) and `ray_hits` (`RAY` true:
/// `a` is the origin, `b` the direction): one body, as the ABI gives both the same signature.
unsafe extern "C" fn hits<T: PluginOracle, const RAY: bool>(
    handle: *const c_void,
    a: DmVec3,
    b: DmVec3,
    out: *mut DmSurfaceHit,
    cap: usize,
    len: *mut usize,
) -> i32 {
    guarded(AssertUnwindSafe(|| {
        // SAFETY: see `oracle`.
        let oracle = unsafe { oracle::<T>(handle) }?;
        HITS.with(|buffer| {
            let mut buffer = buffer.borrow_mut();
            buffer.clear();
            if RAY {
                oracle.ray_hits(a.into(), b.into(), &mut buffer);
            } else {
                oracle.segment_hits(a.into(), b.into(), &mut buffer);
            }
            let items = buffer.iter().map(|h| DmSurfaceHit {
                point: h.point.into(),
                t: h.t,
                patch: h.patch.0,
            });
            // SAFETY: the host passes `cap` slots and one length.
            unsafe { fill(items, out, cap, len) }
        })
    }))
}

/// An entry of a list the oracle gives whole, as the ABI writes it: a surface point of
/// `initial_points` or a corner of `corners`, so that one function, [`list`], serves both slots.
trait ListEntry: Copy + RefUnwindSafe {
    /// The oracle's list, converted.
    fn list<T: PluginOracle>(oracle: &T) -> Vec<Self>;
}

impl ListEntry for DmSurfacePoint {
    fn list<T: PluginOracle>(oracle: &T) -> Vec<Self> {
        let to_abi = |p: &SurfacePoint| DmSurfacePoint {
            point: p.point.into(),
            patch: p.patch.0,
        };
        oracle.initial_points().iter().map(to_abi).collect()
    }
}

impl ListEntry for DmVec3 {
    fn list<T: PluginOracle>(oracle: &T) -> Vec<Self> {
        oracle.corners().into_iter().map(DmVec3::from).collect()
    }
}

/// `initial_points` and `corners`: the oracle's list written into `out`.
unsafe extern "C" fn list<T: PluginOracle, E: ListEntry>(
    handle: *const c_void,
    out: *mut E,
    cap: usize,
    len: *mut usize,
) -> i32 {
    guarded(|| {
        // SAFETY: see `oracle`.
        let entries = E::list(unsafe { oracle::<T>(handle) }?);
        // SAFETY: the host passes `cap` slots and one length.
        unsafe { fill(entries.into_iter(), out, cap, len) }
    })
}

unsafe extern "C" fn feature_curves<T: PluginOracle>(
    handle: *const c_void,
    curves: *mut DmFeatureCurve,
    curves_cap: usize,
    curves_len: *mut usize,
    points: *mut DmVec3,
    points_cap: usize,
    points_len: *mut usize,
) -> i32 {
    guarded(|| {
        // SAFETY: see `oracle`.
        let features = unsafe { oracle::<T>(handle) }?.feature_curves();
        let mut first = 0;
        let table: Vec<DmFeatureCurve> = features
            .iter()
            .map(|c| {
                let entry = DmFeatureCurve {
                    id: c.id.0,
                    closed: u32::from(c.closed),
                    first,
                    len: c.points.len(),
                };
                first += c.points.len();
                entry
            })
            .collect();
        let all_points = features
            .iter()
            .flat_map(|c| c.points.iter().map(|&p| DmVec3::from(p)));
        // SAFETY: the host passes the capacities of both buffers and both lengths.
        let curves_status = unsafe { fill(table.into_iter(), curves, curves_cap, curves_len) }?;
        // SAFETY: as above, for the points buffer.
        let points_status = unsafe {
            fill(
                all_points.collect::<Vec<_>>().into_iter(),
                points,
                points_cap,
                points_len,
            )
        }?;
        Ok(curves_status.max(points_status))
    })
}

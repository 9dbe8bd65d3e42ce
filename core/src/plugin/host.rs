//! Host side: loads a plugin library with libloading, checks its table, and wraps a created
//! oracle as [`DynOracle`], which implements [`Oracle`] like any built-in domain.
//!
//! A plugin is untrusted code in our address space: we cannot survive a segfault in it, but every
//! fault the ABI can express is contained — missing entry point or function, ABI mismatch, failed
//! `create`, a query returning an error (a Rust plugin's panics arrive this way), and outputs that
//! break the contract (NaN, points outside the bounding box, unsorted hits, patch 0).

use super::abi::*;
use crate::kernel::Point3;
use crate::oracle::{
    Aabb, CurveId, FeatureCurve, OUTSIDE, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_void};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Longest error message fetched from a plugin, in bytes.
const MAX_MESSAGE_BYTES: usize = 1 << 16;
/// Most items a plugin may ask room for in one answer (hits, points, curves): far beyond any
/// real oracle, far below an allocation that would abort the process.
const MAX_ITEMS: usize = 1 << 24;
/// Longest plugin message shown, in characters.
const MAX_MESSAGE_CHARS: usize = 200;

/// A plugin's message as one short line: whitespace runs folded, cut to a couple hundred
/// characters.
fn one_line(text: &str) -> String {
    let folded = text.split_whitespace().collect::<Vec<_>>().join(" ");
    match folded.char_indices().nth(MAX_MESSAGE_CHARS) {
        Some((cut, _)) => format!("{}…", &folded[..cut]),
        None => folded,
    }
}

/// Everything that can go wrong with a plugin, always naming it.
#[derive(Debug, Clone, thiserror::Error)]
#[error("plugin {plugin}: {problem}")]
pub struct PluginError {
    /// The plugin's name and library path, or the path alone before the table is read.
    pub plugin: String,
    /// What went wrong.
    pub problem: PluginProblem,
}

/// What went wrong, for callers that react differently (e.g. tests).
#[derive(Debug, Clone, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum PluginProblem {
    #[error("cannot load the library: {0}")]
    Load(String),
    #[error("the library does not export `{DM_ENTRY_SYMBOL}`; is it a delamesh plugin?")]
    MissingEntryPoint,
    #[error(
        "ABI version {found}, this delamesh speaks version {DM_ABI_VERSION}; rebuild the plugin against this delamesh"
    )]
    AbiVersion { found: u32 },
    #[error("malformed plugin table: {0}")]
    BadTable(String),
    #[error("create failed: {0}")]
    Create(String),
    #[error("{query} failed: {message}")]
    Query {
        query: &'static str,
        message: String,
    },
    #[error("{query} broke the contract: {message}")]
    Contract {
        query: &'static str,
        message: String,
    },
}

/// Identity of a plugin, read from its table without creating an oracle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PluginInfo {
    /// The name in the plugin's table.
    pub name: String,
    /// What the plugin meshes, as its table says.
    pub kind: String,
    /// The plugin's own version.
    pub version: String,
    /// The ABI version of the table.
    pub abi_version: u32,
    /// The library file.
    pub path: PathBuf,
}

impl PluginInfo {
    /// How errors name the plugin: its name and where it was loaded from.
    pub fn label(&self) -> String {
        format!("`{}` ({})", self.name, self.path.display())
    }
}

/// The function pointer inside an ABI `Option<fn>` type, for entries checked to be non-null.
trait NonNull {
    type Function;
}
impl<F> NonNull for Option<F> {
    type Function = F;
}
type Checked<F> = <F as NonNull>::Function;

/// The checked function table: required entries are non-null here, so calls need no re-checks.
#[derive(Clone, Copy)]
struct Functions {
    create: Checked<DmCreateFn>,
    destroy: Checked<DmDestroyFn>,
    last_error: Checked<DmLastErrorFn>,
    bounding_box: Checked<DmBoundingBoxFn>,
    subdomains: Checked<DmSubdomainsFn>,
    segment_hits: Checked<DmHitsFn>,
    ray_hits: Checked<DmHitsFn>,
    initial_points: Checked<DmInitialPointsFn>,
    feature_curves: DmFeatureCurvesFn,
    corners: DmCornersFn,
}

/// A loaded plugin library whose table passed the checks. Create oracles from it with
/// [`PluginLibrary::create`]; they keep the library loaded.
pub struct PluginLibrary {
    info: PluginInfo,
    functions: Functions,
    library: Arc<libloading::Library>,
}

/// Reads a static NUL-terminated UTF-8 string from the table.
///
/// # Safety
/// `ptr` is null or points to a NUL-terminated string that outlives the call.
unsafe fn table_string(ptr: *const c_char, field: &str) -> Result<String, PluginProblem> {
    if ptr.is_null() {
        return Err(PluginProblem::BadTable(format!("`{field}` is null")));
    }
    // SAFETY: per the function contract.
    let text = unsafe { CStr::from_ptr(ptr) };
    text.to_str()
        .map(str::to_string)
        .map_err(|_| PluginProblem::BadTable(format!("`{field}` is not UTF-8")))
}

impl PluginLibrary {
    /// Loads the library at `path` and checks its entry point and table.
    pub fn open(path: &Path) -> Result<Self, PluginError> {
        let fail = |problem| PluginError {
            plugin: path.display().to_string(),
            problem,
        };
        // SAFETY: loading runs the library's initialisers; that is the trust a user grants by
        // naming a plugin on the command line.
        let library = unsafe { libloading::Library::new(path) }
            .map_err(|e| fail(PluginProblem::Load(e.to_string())))?;
        // SAFETY: the symbol has the type the ABI specifies for it.
        let entry: DmPluginEntryV1 =
            unsafe { library.get::<DmPluginEntryV1>(DM_ENTRY_SYMBOL.as_bytes()) }
                .map(|symbol| *symbol)
                .map_err(|_| fail(PluginProblem::MissingEntryPoint))?;
        // SAFETY: the entry point takes no arguments and returns a static table or null.
        let table = unsafe { entry() };
        if table.is_null() {
            return Err(fail(PluginProblem::BadTable(
                "the entry point returned null".into(),
            )));
        }
        // The two leading fields are stable across every ABI version: read them before the rest.
        // SAFETY: `table` points to a table of at least these two fields.
        let (abi_version, struct_size) = unsafe { ((*table).abi_version, (*table).struct_size) };
        if abi_version != DM_ABI_VERSION {
            return Err(fail(PluginProblem::AbiVersion { found: abi_version }));
        }
        if (struct_size as usize) < size_of::<DmPluginV1>() {
            return Err(fail(PluginProblem::BadTable(format!(
                "struct_size is {struct_size}, a version-{DM_ABI_VERSION} table has {} bytes",
                size_of::<DmPluginV1>()
            ))));
        }
        // SAFETY: version and size checked: `table` is a whole `DmPluginV1`.
        let table = unsafe { &*table };
        // SAFETY: the table's strings are static in the library, which `library` keeps loaded.
        let strings = unsafe {
            (
                table_string(table.name, "name"),
                table_string(table.kind, "kind"),
                table_string(table.version, "version"),
            )
        };
        let (name, kind, version) = match strings {
            (Ok(n), Ok(k), Ok(v)) => (n, k, v),
            (Err(e), _, _) | (_, Err(e), _) | (_, _, Err(e)) => return Err(fail(e)),
        };
        let info = PluginInfo {
            name,
            kind,
            version,
            abi_version,
            path: path.to_path_buf(),
        };
        let missing = |function: &str| PluginError {
            plugin: info.label(),
            problem: PluginProblem::BadTable(format!("required function `{function}` is null")),
        };
        let functions = Functions {
            create: table.create.ok_or_else(|| missing("create"))?,
            destroy: table.destroy.ok_or_else(|| missing("destroy"))?,
            last_error: table.last_error.ok_or_else(|| missing("last_error"))?,
            bounding_box: table.bounding_box.ok_or_else(|| missing("bounding_box"))?,
            subdomains: table.subdomains.ok_or_else(|| missing("subdomains"))?,
            segment_hits: table.segment_hits.ok_or_else(|| missing("segment_hits"))?,
            ray_hits: table.ray_hits.ok_or_else(|| missing("ray_hits"))?,
            initial_points: table
                .initial_points
                .ok_or_else(|| missing("initial_points"))?,
            feature_curves: table.feature_curves,
            corners: table.corners,
        };
        Ok(PluginLibrary {
            info,
            functions,
            library: Arc::new(library),
        })
    }

    /// The plugin's identity, read when the library was opened.
    pub fn info(&self) -> &PluginInfo {
        &self.info
    }

    /// Builds an oracle from `config`, then asks for its bounding box (which every later answer
    /// is checked against).
    pub fn create(&self, config: &str) -> Result<DynOracle, PluginError> {
        let fail = |problem| PluginError {
            plugin: self.info.label(),
            problem,
        };
        let config = CString::new(config).map_err(|_| {
            fail(PluginProblem::Create(
                "configuration contains a NUL byte".into(),
            ))
        })?;
        let mut message = vec![0 as c_char; 1024];
        // SAFETY: `config` is NUL-terminated and `message` has the capacity we pass.
        let handle = unsafe {
            (self.functions.create)(config.as_ptr(), message.as_mut_ptr(), message.len())
        };
        if handle.is_null() {
            // Force termination in case the plugin filled the whole buffer without a NUL.
            if let Some(last) = message.last_mut() {
                *last = 0;
            }
            // SAFETY: `message` is NUL-terminated.
            let text = one_line(&unsafe { CStr::from_ptr(message.as_ptr()) }.to_string_lossy());
            let text = if text.is_empty() {
                "no message".to_string()
            } else {
                text
            };
            return Err(fail(PluginProblem::Create(text)));
        }
        let mut oracle = DynOracle {
            label: self.info.label(),
            functions: self.functions,
            handle,
            bbox: Aabb {
                min: Point3::ZERO,
                max: Point3::ZERO,
            },
            slack: 0.0,
            fault: OnceLock::new(),
            _library: Arc::clone(&self.library),
        };
        let bbox = oracle.try_bounding_box()?;
        oracle.slack = 1e-9 * bbox.diagonal().max(f64::MIN_POSITIVE);
        oracle.bbox = bbox;
        Ok(oracle)
    }
}

/// Which of the plugin's two hit queries [`DynOracle::try_hits`] makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HitQuery {
    /// `segment_hits`: the crossings of the closed segment `[a, b]`.
    Segment,
    /// `ray_hits`: the crossings of the ray `a + t b`, `t ≥ 0`.
    Ray,
}

/// An oracle living in a plugin library. Implements [`Oracle`]; every answer is checked against
/// the contract. The trait's methods cannot fail, so the first fault is recorded (see
/// [`DynOracle::fault`]) and a neutral answer returned — outside, no hits — which makes
/// refinement wind down; callers check [`DynOracle::check`] before using the result. The `try_`
/// methods return the fault directly.
pub struct DynOracle {
    label: String,
    functions: Functions,
    handle: *mut c_void,
    bbox: Aabb,
    /// Rounding allowance for "inside the bounding box" checks.
    slack: f64,
    fault: OnceLock<PluginError>,
    _library: Arc<libloading::Library>,
}

// SAFETY: the plugin contract (PLUGINS.md) requires queries on one handle to be safe from several
// threads at once, and `destroy` runs only from `Drop`, i.e. with exclusive access.
unsafe impl Send for DynOracle {}
// SAFETY: as above.
unsafe impl Sync for DynOracle {}

impl Drop for DynOracle {
    fn drop(&mut self) {
        // SAFETY: `handle` came from this library's `create` and is destroyed once; the library
        // is unloaded only after this (the `_library` field drops after `drop` returns).
        unsafe { (self.functions.destroy)(self.handle) }
    }
}

thread_local! {
    static HIT_BUFFER: RefCell<Vec<DmSurfaceHit>> = const { RefCell::new(Vec::new()) };
}

impl DynOracle {
    /// The first fault met by an infallible [`Oracle`] method, if any.
    pub fn fault(&self) -> Option<&PluginError> {
        self.fault.get()
    }

    /// `Err` with the first fault if any [`Oracle`] method met one.
    pub fn check(&self) -> Result<(), PluginError> {
        self.fault.get().map_or(Ok(()), |e| Err(e.clone()))
    }

    fn error(&self, problem: PluginProblem) -> PluginError {
        PluginError {
            plugin: self.label.clone(),
            problem,
        }
    }

    fn contract(&self, query: &'static str, message: String) -> PluginError {
        self.error(PluginProblem::Contract { query, message })
    }

    /// Turns a status into a result, fetching the plugin's message on error.
    fn status(&self, query: &'static str, status: i32) -> Result<(), PluginError> {
        match status {
            DM_OK => Ok(()),
            DM_ERROR => {
                let mut buf = vec![0 as c_char; 512];
                // SAFETY: `buf` has the capacity we pass.
                let full = unsafe {
                    (self.functions.last_error)(self.handle, buf.as_mut_ptr(), buf.len())
                };
                if full >= buf.len() {
                    // A plugin reporting `usize::MAX` must not make `full + 1` wrap.
                    buf = vec![0 as c_char; full.min(MAX_MESSAGE_BYTES) + 1];
                    // SAFETY: as above.
                    unsafe {
                        (self.functions.last_error)(self.handle, buf.as_mut_ptr(), buf.len())
                    };
                }
                if let Some(last) = buf.last_mut() {
                    *last = 0;
                }
                // SAFETY: `buf` is NUL-terminated.
                let message = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_string_lossy();
                let message = one_line(&message);
                Err(self.error(PluginProblem::Query { query, message }))
            }
            other => Err(self.contract(query, format!("returned unknown status {other}"))),
        }
    }

    /// Records the first fault and returns the neutral answer.
    fn recorded<T>(&self, result: Result<T, PluginError>, neutral: T) -> T {
        result.unwrap_or_else(|e| {
            let _ = self.fault.set(e);
            neutral
        })
    }

    fn check_point(&self, query: &'static str, p: Point3) -> Result<Point3, PluginError> {
        if !p.is_finite() {
            return Err(self.contract(query, format!("returned a non-finite point {p}")));
        }
        let (lo, hi) = (self.bbox.min - self.slack, self.bbox.max + self.slack);
        if !(p.cmpge(lo).all() && p.cmple(hi).all()) {
            return Err(self.contract(
                query,
                format!(
                    "returned the point {p} outside its bounding box [{}, {}]",
                    self.bbox.min, self.bbox.max
                ),
            ));
        }
        Ok(p)
    }

    fn check_patch(&self, query: &'static str, patch: u32) -> Result<PatchId, PluginError> {
        if patch == 0 {
            return Err(self.contract(
                query,
                "returned patch id 0 (patches are numbered from 1)".into(),
            ));
        }
        Ok(PatchId(patch))
    }

    /// Calls a capacity-protocol query with `buffer` as its output, growing it once if the plugin
    /// asks for more room; returns how many leading items of `buffer` the plugin wrote. The buffer
    /// stays fully initialised (never shrunk, grown with defaults), so even a plugin that lies
    /// about its count cannot make us read uninitialised memory.
    fn fill_buffer<T: Copy + Default>(
        &self,
        query: &'static str,
        buffer: &mut Vec<T>,
        mut call: impl FnMut(*mut T, usize, *mut usize) -> i32,
    ) -> Result<usize, PluginError> {
        if buffer.len() < 16 {
            buffer.resize(16, T::default());
        }
        for _attempt in 0..2 {
            let mut len = 0;
            let status = call(buffer.as_mut_ptr(), buffer.len(), &mut len);
            if status == DM_BUFFER_TOO_SMALL && len > buffer.len() {
                if len > MAX_ITEMS {
                    return Err(self.contract(
                        query,
                        format!("asked for room for {len} items (at most {MAX_ITEMS})"),
                    ));
                }
                buffer.resize(len, T::default());
                continue;
            }
            self.status(query, status)?;
            if len > buffer.len() {
                return Err(self.contract(
                    query,
                    format!("reported {len} items for a buffer of {}", buffer.len()),
                ));
            }
            return Ok(len);
        }
        Err(self.contract(query, "asked for a larger buffer twice".into()))
    }

    /// [`Oracle::bounding_box`], with the plugin's failure as an error rather than recorded.
    pub fn try_bounding_box(&self) -> Result<Aabb, PluginError> {
        let mut out = DmAabb::default();
        // SAFETY: `out` is valid for one write.
        self.status("bounding_box", unsafe {
            (self.functions.bounding_box)(self.handle, &mut out)
        })?;
        let (min, max) = (Point3::from(out.min), Point3::from(out.max));
        if !(min.is_finite() && max.is_finite() && min.cmple(max).all()) {
            return Err(self.contract(
                "bounding_box",
                format!("returned an invalid box [{min}, {max}]"),
            ));
        }
        Ok(Aabb { min, max })
    }

    /// Batch point location: one call into the plugin for all of `points`.
    ///
    /// # Panics
    /// If `out` and `points` differ in length (a caller bug, not a plugin fault).
    pub fn try_subdomains(
        &self,
        points: &[Point3],
        out: &mut [SubdomainId],
    ) -> Result<(), PluginError> {
        assert_eq!(points.len(), out.len(), "one label per point");
        // `DmVec3` and `DVec3` are both three packed f64; converting costs one copy and keeps the
        // ABI independent of glam's layout.
        let points: Vec<DmVec3> = points.iter().map(|&p| p.into()).collect();
        // SAFETY: `points` and `out` hold `len` elements each; `SubdomainId` is a transparent
        // `u32`, the label type of the ABI.
        let status = unsafe {
            (self.functions.subdomains)(
                self.handle,
                points.as_ptr(),
                points.len(),
                out.as_mut_ptr().cast::<u32>(),
            )
        };
        self.status("subdomains", status)
    }

    /// [`Oracle::subdomain`], with the plugin's failure as an error rather than recorded.
    pub fn try_subdomain(&self, p: Point3) -> Result<SubdomainId, PluginError> {
        let mut label = OUTSIDE.0;
        let point = DmVec3::from(p);
        // SAFETY: one point in, one label out.
        let status = unsafe { (self.functions.subdomains)(self.handle, &point, 1, &mut label) };
        self.status("subdomains", status)?;
        Ok(SubdomainId(label))
    }

    /// [`Oracle::segment_hits`] (`a` and `b` the ends) or [`Oracle::ray_hits`] (`a` the origin,
    /// `b` the direction), with the plugin's failure as an error rather than recorded.
    pub fn try_hits(
        &self,
        kind: HitQuery,
        a: Point3,
        b: Point3,
        out: &mut Vec<SurfaceHit>,
    ) -> Result<(), PluginError> {
        let (query, function, t_max) = match kind {
            HitQuery::Segment => ("segment_hits", self.functions.segment_hits, 1.0),
            HitQuery::Ray => ("ray_hits", self.functions.ray_hits, f64::INFINITY),
        };
        HIT_BUFFER.with(|buffer| {
            let mut buffer = buffer.borrow_mut();
            let (da, db) = (DmVec3::from(a), DmVec3::from(b));
            // SAFETY: the closure passes a buffer of `cap` hits and one length.
            let len = self.fill_buffer(query, &mut buffer, |ptr, cap, len| unsafe {
                function(self.handle, da, db, ptr, cap, len)
            })?;
            let mut previous_t = f64::NEG_INFINITY;
            for hit in &buffer[..len] {
                let point = self.check_point(query, hit.point.into())?;
                if !(hit.t >= 0.0 && hit.t <= t_max) || hit.t < previous_t {
                    return Err(self.contract(
                        query,
                        format!("returned t = {} (must be sorted, in [0, {t_max}])", hit.t),
                    ));
                }
                previous_t = hit.t;
                out.push(SurfaceHit {
                    point,
                    t: hit.t,
                    patch: self.check_patch(query, hit.patch)?,
                });
            }
            Ok(())
        })
    }

    /// [`Self::try_hits`] for the `Oracle` methods: on a failure `out` is left as it was and the
    /// failure recorded.
    fn recorded_hits(&self, kind: HitQuery, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
        let start = out.len();
        if let Err(e) = self.try_hits(kind, a, b, out) {
            out.truncate(start);
            self.recorded(Err(e), ());
        }
    }

    /// [`Oracle::initial_points`], with the plugin's failure as an error rather than recorded.
    pub fn try_initial_points(&self) -> Result<Vec<SurfacePoint>, PluginError> {
        const QUERY: &str = "initial_points";
        let mut buffer = Vec::new();
        // SAFETY: the closure passes a buffer of `cap` points and one length.
        let len = self.fill_buffer(QUERY, &mut buffer, |ptr, cap, len| unsafe {
            (self.functions.initial_points)(self.handle, ptr, cap, len)
        })?;
        if len == 0 {
            return Err(self.contract(
                QUERY,
                "returned no points; the mesher needs some on every component".into(),
            ));
        }
        buffer[..len]
            .iter()
            .map(|p| {
                Ok(SurfacePoint {
                    point: self.check_point(QUERY, p.point.into())?,
                    patch: self.check_patch(QUERY, p.patch)?,
                })
            })
            .collect()
    }

    /// [`Oracle::corners`], with the plugin's failure as an error rather than recorded.
    pub fn try_corners(&self) -> Result<Vec<Point3>, PluginError> {
        let Some(corners) = self.functions.corners else {
            return Ok(Vec::new());
        };
        let mut buffer = Vec::new();
        // SAFETY: the closure passes a buffer of `cap` points and one length.
        let len = self.fill_buffer("corners", &mut buffer, |ptr, cap, len| unsafe {
            corners(self.handle, ptr, cap, len)
        })?;
        buffer[..len]
            .iter()
            .map(|&p| self.check_point("corners", p.into()))
            .collect()
    }

    /// [`Oracle::feature_curves`], with the plugin's failure as an error rather than recorded.
    pub fn try_feature_curves(&self) -> Result<Vec<FeatureCurve>, PluginError> {
        const QUERY: &str = "feature_curves";
        let Some(features) = self.functions.feature_curves else {
            return Ok(Vec::new());
        };
        let (mut curves, mut points) = (
            vec![DmFeatureCurve::default(); 16],
            vec![DmVec3::default(); 256],
        );
        for _attempt in 0..2 {
            let (mut n_curves, mut n_points) = (0, 0);
            // SAFETY: both buffers have the capacities we pass.
            let status = unsafe {
                features(
                    self.handle,
                    curves.as_mut_ptr(),
                    curves.len(),
                    &mut n_curves,
                    points.as_mut_ptr(),
                    points.len(),
                    &mut n_points,
                )
            };
            if status == DM_BUFFER_TOO_SMALL && (n_curves > curves.len() || n_points > points.len())
            {
                if n_curves > MAX_ITEMS || n_points > MAX_ITEMS {
                    return Err(self.contract(
                        QUERY,
                        format!(
                            "asked for room for {n_curves} curves and {n_points} points \
                             (at most {MAX_ITEMS} each)"
                        ),
                    ));
                }
                curves.resize(n_curves.max(curves.len()), DmFeatureCurve::default());
                points.resize(n_points.max(points.len()), DmVec3::default());
                continue;
            }
            self.status(QUERY, status)?;
            if n_curves > curves.len() || n_points > points.len() {
                return Err(
                    self.contract(QUERY, "reported more items than the buffers hold".into())
                );
            }
            return curves[..n_curves]
                .iter()
                .map(|c| {
                    let range = c
                        .first
                        .checked_add(c.len)
                        .filter(|&end| end <= n_points)
                        .map(|end| c.first..end);
                    let range = range.ok_or_else(|| {
                        self.contract(QUERY, format!("curve {} indexes past the points", c.id))
                    })?;
                    let curve_points = points[range]
                        .iter()
                        .map(|&p| self.check_point(QUERY, p.into()))
                        .collect::<Result<_, _>>()?;
                    Ok(FeatureCurve {
                        id: CurveId(c.id),
                        points: curve_points,
                        closed: c.closed != 0,
                    })
                })
                .collect();
        }
        Err(self.contract(QUERY, "asked for larger buffers twice".into()))
    }

    /// Exercises every query once on simple inputs (box centre and corners, box diagonals, the
    /// initial points), so that a broken plugin fails before meshing starts, with a clear error.
    pub fn self_check(&self) -> Result<(), PluginError> {
        let Aabb { min, max } = self.bbox;
        let corners: Vec<Point3> = (0..8)
            .map(|i| {
                Point3::new(
                    [min.x, max.x][i & 1],
                    [min.y, max.y][(i >> 1) & 1],
                    [min.z, max.z][i >> 2],
                )
            })
            .collect();
        let mut probes = corners.clone();
        probes.push(self.bbox.center());
        let mut labels = vec![OUTSIDE; probes.len()];
        self.try_subdomains(&probes, &mut labels)?;
        let mut hits = Vec::new();
        for i in 0..4 {
            self.try_hits(HitQuery::Segment, corners[i], corners[7 - i], &mut hits)?;
            let center = self.bbox.center();
            self.try_hits(HitQuery::Ray, center, corners[i] - center, &mut hits)?;
        }
        self.try_initial_points()?;
        self.try_corners()?;
        self.try_feature_curves()?;
        Ok(())
    }
}

impl Oracle for DynOracle {
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    fn subdomain(&self, p: Point3) -> SubdomainId {
        self.recorded(self.try_subdomain(p), OUTSIDE)
    }

    fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
        self.recorded_hits(HitQuery::Segment, a, b, out);
    }

    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
        self.recorded_hits(HitQuery::Ray, origin, dir, out);
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        self.recorded(self.try_initial_points(), Vec::new())
    }

    fn feature_curves(&self) -> Vec<FeatureCurve> {
        self.recorded(self.try_feature_curves(), Vec::new())
    }

    fn corners(&self) -> Vec<Point3> {
        self.recorded(self.try_corners(), Vec::new())
    }
}

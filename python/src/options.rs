//! The keyword options of `delamesh.mesh`: the long options of `delamesh mesh` with underscores,
//! in one table mapping each to the facade's [`MeshSettings`]. Values are checked as the command
//! line checks them (the settings' own validation, with the flag named in the message).

use crate::Error;
use delamesh::core::optimize::Flips;
use delamesh::image_label::Interpolation;
use delamesh::subdivision::Scheme;
use delamesh::{MeshSettings, SizeSource};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::BTreeMap;
use std::time::Duration;

/// One keyword option: its name and how it sets the settings.
pub struct Opt {
    /// The keyword (the command line's flag, `-` → `_`, without the dashes).
    pub name: &'static str,
    set: fn(&mut MeshSettings, &Bound<'_, PyAny>) -> Result<(), String>,
}

/// An [`Opt`] for the keyword `$name` whose `set` runs `$set` (which may return an error early).
macro_rules! opt {
    ($name:ident, |$s:ident, $v:ident| $set:expr) => {
        Opt {
            name: stringify!($name),
            set: |$s, $v| {
                $set;
                Ok(())
            },
        }
    };
}

/// The keyword options, in the order of `delamesh mesh --help`.
#[rustfmt::skip]
pub const OPTIONS: &[Opt] = &[
    opt!(edge_size, |s, v| s.edge_size = Some(number(v)?)),
    opt!(edge_min_size, |s, v| s.edge_min_size = Some(number(v)?)),
    opt!(facet_angle, |s, v| s.facet_angle = Some(number(v)?)),
    opt!(facet_size, |s, v| s.facet_size = Some(number(v)?)),
    opt!(facet_distance, |s, v| s.facet_distance = Some(number(v)?)),
    opt!(cell_radius_edge_ratio, |s, v| s.cell_radius_edge_ratio = Some(number(v)?)),
    opt!(cell_size, |s, v| s.cell_size = Some(number(v)?)),
    opt!(max_vertices, |s, v| s.max_vertices = Some(count(v)?)),
    opt!(time_limit, |s, v| s.time_limit = Some(seconds(v)?)),
    opt!(keep_partial, |s, v| s.keep_partial = flag(v)?),
    opt!(non_manifold, |s, v| s.non_manifold = flag(v)?),
    opt!(feature_angle, |s, v| s.features.angle_deg = number(v)?),
    opt!(features, |s, v| s.features.polylines =
        Some(v.extract().map_err(|_| "expected a path".to_string())?)),
    opt!(no_features, |s, v| s.features.enabled = !flag(v)?),
    opt!(strict, |s, v| s.strict = flag(v)?),
    opt!(background, |s, v| s.image.options.background = label(v)?),
    opt!(isovalue, |s, v| s.image.options.isovalue = Some(number(v)?)),
    opt!(cell_size_per_label, |s, v| s.image.cell_size_per_label = per_label(v)?),
    opt!(label_interpolation, |s, v| s.image.options.interpolation = interpolation(v)?),
    opt!(no_perturb, |s, v| s.optimize.perturb = !flag(v)?),
    opt!(no_exude, |s, v| s.optimize.exude = !flag(v)?),
    opt!(perturb, |s, v| s.optimize.perturb = flag(v)?),
    opt!(exude, |s, v| s.optimize.exude = flag(v)?),
    opt!(odt, |s, v| s.optimize.odt = flag(v)?),
    opt!(lloyd, |s, v| s.optimize.lloyd = flag(v)?),
    opt!(flip, |s, v| s.optimize.flip = if flag(v)? { Flips::All } else { Flips::Slivers }),
    opt!(no_flip, |s, v| if flag(v)? { s.optimize.flip = Flips::Off }),
    opt!(optimize_time, |s, v| s.optimize.time_limit = Some(seconds(v)?)),
    opt!(sizing, |s, v| {
        s.sizing.field = Some(match crate::sizing::source(v)? {
            Some(source) => source,
            None => SizeSource::file(path(v)?),
        });
    }),
    // After `sizing` in this table: options are applied in table order, whatever the keyword
    // order.
    opt!(sizing_field, |s, v| match &mut s.sizing.field {
        Some(SizeSource::File { field, .. }) => *field = Some(text(v)?),
        _ => return Err("needs sizing= a background mesh file".into()),
    }),
    opt!(sizing_expr, |s, v| s.sizing.field = Some(SizeSource::Expression(text(v)?))),
    opt!(size_per_subdomain, |s, v| s.sizing.per_subdomain = per_label(v)?),
    opt!(size_per_patch, |s, v| s.sizing.per_patch = per_label(v)?),
    opt!(size_gradation, |s, v| s.sizing.gradation = Some(number(v)?)),
    opt!(distance_field, |s, v| s.sizing.distance = Some(SizeSource::file(path(v)?))),
    opt!(distance_expr, |s, v| s.sizing.distance = Some(SizeSource::Expression(text(v)?))),
    opt!(subdivision, |s, v| {
        let scheme = match text(v)?.as_str() {
            "auto" => None,
            other => Some(other.parse::<Scheme>()?),
        };
        let enabled = s.features.enabled;
        let sub = s.subdivision.get_or_insert_with(Default::default);
        sub.scheme = scheme;
        // As on the command line: `no_features` also turns the group creases off.
        sub.group_creases = enabled;
    }),
    // After `subdivision` in this table (see `sizing_field`).
    opt!(crease_angle, |s, v| match &mut s.subdivision {
        Some(sub) => sub.crease_angle_deg = Some(number(v)?),
        None => return Err("needs subdivision=".into()),
    }),
    opt!(preserve_surface, |s, v| s.preserve_surface = flag(v)?),
    opt!(merge_coplanar, |s, v| s.merge_coplanar = flag(v)?),
];

fn path(v: &Bound<'_, PyAny>) -> Result<std::path::PathBuf, String> {
    v.extract()
        .map_err(|_| format!("expected a path, got {}", describe(v)))
}

fn text(v: &Bound<'_, PyAny>) -> Result<String, String> {
    v.extract()
        .map_err(|_| format!("expected a string, got {}", describe(v)))
}

fn number(v: &Bound<'_, PyAny>) -> Result<f64, String> {
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Err("expected a number, got a bool".into());
    }
    v.extract::<f64>()
        .map_err(|_| format!("expected a number, got {}", describe(v)))
}

fn count(v: &Bound<'_, PyAny>) -> Result<usize, String> {
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Err("expected a count, got a bool".into());
    }
    v.extract::<usize>()
        .map_err(|_| format!("expected a whole number ≥ 0, got {}", describe(v)))
}

fn label(v: &Bound<'_, PyAny>) -> Result<u32, String> {
    v.extract::<u32>()
        .map_err(|_| format!("expected a label (a whole number ≥ 0), got {}", describe(v)))
}

fn flag(v: &Bound<'_, PyAny>) -> Result<bool, String> {
    v.extract::<bool>()
        .map_err(|_| format!("expected True or False, got {}", describe(v)))
}

/// A positive number of seconds, as the command line takes it.
fn seconds(v: &Bound<'_, PyAny>) -> Result<Duration, String> {
    let t = number(v)?;
    if t.is_finite() && t > 0.0 && t < 1e9 {
        Ok(Duration::from_secs_f64(t))
    } else {
        Err(format!("must be a positive number of seconds, got {t}"))
    }
}

/// `{label: size}` (the sizes are validated with the other settings).
fn per_label(v: &Bound<'_, PyAny>) -> Result<BTreeMap<u32, f64>, String> {
    v.extract::<BTreeMap<u32, f64>>()
        .map_err(|_| format!("expected a dict {{label: size}}, got {}", describe(v)))
}

fn interpolation(v: &Bound<'_, PyAny>) -> Result<Interpolation, String> {
    match v.extract::<String>().as_deref() {
        Ok("nearest") => Ok(Interpolation::Nearest),
        Ok("trilinear") => Ok(Interpolation::Trilinear),
        _ => Err(format!(
            "expected 'nearest' or 'trilinear', got {}",
            describe(v)
        )),
    }
}

/// A value as Python prints it (`repr`), for messages.
fn describe(v: &Bound<'_, PyAny>) -> String {
    v.repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "a value of another type".into())
}

/// The settings of the keyword options in `options`: the command line's defaults, each option
/// set from its keyword, then validated. An unknown keyword or a bad value is a
/// [`Error`](crate::Error) naming it.
pub fn settings(options: Option<&Bound<'_, PyDict>>) -> PyResult<MeshSettings> {
    let mut settings = MeshSettings::default();
    let mut given = Vec::new();
    for (key, value) in options.into_iter().flatten() {
        let name: String = key.extract()?;
        let Some(k) = OPTIONS.iter().position(|o| o.name == name) else {
            let known: Vec<&str> = OPTIONS.iter().map(|o| o.name).collect();
            return Err(Error::new_err(format!(
                "unknown option `{name}` (known: {})",
                known.join(", ")
            )));
        };
        given.push((k, value));
    }
    // In table order, so that an option refining another (`sizing_field`) finds it set.
    given.sort_by_key(|&(k, _)| k);
    for (k, value) in given {
        let opt = &OPTIONS[k];
        (opt.set)(&mut settings, &value).map_err(|problem| {
            Error::new_err(format!("--{} {problem}", opt.name.replace('_', "-")))
        })?;
    }
    settings.validate().map_err(|e| crate::error(&e))?;
    Ok(settings)
}

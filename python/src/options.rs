//! The keyword options of `delamesh.mesh`: the long options of `delamesh mesh` with underscores,
//! in one table mapping each to the facade's [`MeshSettings`]. Values are checked as the command
//! line checks them (the settings' own validation, with the flag named in the message).

use crate::Error;
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

/// The keyword options, in the order of `delamesh mesh --help`.
pub const OPTIONS: &[Opt] = &[
    Opt {
        name: "edge_size",
        set: |s, v| {
            s.edge_size = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "edge_min_size",
        set: |s, v| {
            s.edge_min_size = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "facet_angle",
        set: |s, v| {
            s.facet_angle = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "facet_size",
        set: |s, v| {
            s.facet_size = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "facet_distance",
        set: |s, v| {
            s.facet_distance = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "cell_radius_edge_ratio",
        set: |s, v| {
            s.cell_radius_edge_ratio = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "cell_size",
        set: |s, v| {
            s.cell_size = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "max_vertices",
        set: |s, v| {
            s.max_vertices = Some(count(v)?);
            Ok(())
        },
    },
    Opt {
        name: "time_limit",
        set: |s, v| {
            s.time_limit = Some(seconds(v)?);
            Ok(())
        },
    },
    Opt {
        name: "keep_partial",
        set: |s, v| {
            s.keep_partial = flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "non_manifold",
        set: |s, v| {
            s.non_manifold = flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "feature_angle",
        set: |s, v| {
            s.features.angle_deg = number(v)?;
            Ok(())
        },
    },
    Opt {
        name: "features",
        set: |s, v| {
            s.features.polylines = Some(v.extract().map_err(|_| "expected a path".to_string())?);
            Ok(())
        },
    },
    Opt {
        name: "no_features",
        set: |s, v| {
            s.features.enabled = !flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "strict",
        set: |s, v| {
            s.strict = flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "background",
        set: |s, v| {
            s.image.options.background = label(v)?;
            Ok(())
        },
    },
    Opt {
        name: "isovalue",
        set: |s, v| {
            s.image.options.isovalue = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "cell_size_per_label",
        set: |s, v| {
            s.image.cell_size_per_label = per_label(v)?;
            Ok(())
        },
    },
    Opt {
        name: "label_interpolation",
        set: |s, v| {
            s.image.options.interpolation = interpolation(v)?;
            Ok(())
        },
    },
    Opt {
        name: "no_perturb",
        set: |s, v| {
            s.optimize.perturb = !flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "no_exude",
        set: |s, v| {
            s.optimize.exude = !flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "perturb",
        set: |s, v| {
            s.optimize.perturb = flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "exude",
        set: |s, v| {
            s.optimize.exude = flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "odt",
        set: |s, v| {
            s.optimize.odt = flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "lloyd",
        set: |s, v| {
            s.optimize.lloyd = flag(v)?;
            Ok(())
        },
    },
    Opt {
        name: "optimize_time",
        set: |s, v| {
            s.optimize.time_limit = Some(seconds(v)?);
            Ok(())
        },
    },
    Opt {
        name: "sizing",
        set: |s, v| {
            s.sizing.field = Some(match crate::sizing::source(v)? {
                Some(source) => source,
                None => SizeSource::file(path(v)?),
            });
            Ok(())
        },
    },
    // After `sizing` in this table: options are applied in table order, whatever the keyword
    // order.
    Opt {
        name: "sizing_field",
        set: |s, v| match &mut s.sizing.field {
            Some(SizeSource::File { field, .. }) => {
                *field = Some(text(v)?);
                Ok(())
            }
            _ => Err("needs sizing= a background mesh file".into()),
        },
    },
    Opt {
        name: "sizing_expr",
        set: |s, v| {
            s.sizing.field = Some(SizeSource::Expression(text(v)?));
            Ok(())
        },
    },
    Opt {
        name: "size_per_subdomain",
        set: |s, v| {
            s.sizing.per_subdomain = per_label(v)?;
            Ok(())
        },
    },
    Opt {
        name: "size_per_patch",
        set: |s, v| {
            s.sizing.per_patch = per_label(v)?;
            Ok(())
        },
    },
    Opt {
        name: "size_gradation",
        set: |s, v| {
            s.sizing.gradation = Some(number(v)?);
            Ok(())
        },
    },
    Opt {
        name: "distance_field",
        set: |s, v| {
            s.sizing.distance = Some(SizeSource::file(path(v)?));
            Ok(())
        },
    },
    Opt {
        name: "distance_expr",
        set: |s, v| {
            s.sizing.distance = Some(SizeSource::Expression(text(v)?));
            Ok(())
        },
    },
    Opt {
        name: "subdivision",
        set: |s, v| {
            let scheme = match text(v)?.as_str() {
                "auto" => None,
                other => Some(other.parse::<Scheme>()?),
            };
            let enabled = s.features.enabled;
            let sub = s.subdivision.get_or_insert_with(Default::default);
            sub.scheme = scheme;
            // As on the command line: `no_features` also turns the group creases off.
            sub.group_creases = enabled;
            Ok(())
        },
    },
    // After `subdivision` in this table (see `sizing_field`).
    Opt {
        name: "crease_angle",
        set: |s, v| match &mut s.subdivision {
            Some(sub) => {
                sub.crease_angle_deg = Some(number(v)?);
                Ok(())
            }
            None => Err("needs subdivision=".into()),
        },
    },
    Opt {
        name: "preserve_surface",
        set: |s, v| {
            s.preserve_surface = flag(v)?;
            Ok(())
        },
    },
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

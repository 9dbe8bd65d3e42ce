//! From voxel values to classes: the labels of a segmented image, or the two sides of an
//! isovalue of a gray-level one.

use crate::ImageLabelError;
use crate::grid::{Class, ClassGrid, Interpolation};
use delamesh_core::oracle::{OUTSIDE, SubdomainId};
use delamesh_formats::image::{Image, Voxels};
use rayon::prelude::*;

/// Voxels per parallel task of the passes over a whole image.
const CHUNK: usize = 1 << 20;

/// Most labels an image may have: class pairs number the interface patches, which must fit a
/// `u32` (65 535 labels give about 2.1 × 10⁹ pairs).
pub const MAX_LABELS: usize = 65_535;

/// A voxel value as a label: a non-negative integer below 2³² (every stored type converts to
/// `f64` exactly; NaN is none). The one rule of what is a label, for the mesher and for
/// `delamesh info`.
pub fn label_value(v: f64) -> Option<u32> {
    (v.fract() == 0.0 && (0.0..f64::from(u32::MAX)).contains(&v)).then_some(v as u32)
}

/// The class grid in the narrowest type that holds every class.
pub(crate) enum Field {
    U8(ClassGrid<u8>),
    U16(ClassGrid<u16>),
}

/// A class type a [`Field`] holds: how a class number (below the type's range, checked by the
/// caller) narrows to it, and the field's variant for it.
trait FieldClass: Class + From<u8> {
    fn narrow(class: usize) -> Self;
    fn field(grid: ClassGrid<Self>) -> Field;
}

impl FieldClass for u8 {
    fn narrow(class: usize) -> Self {
        class as u8
    }
    fn field(grid: ClassGrid<Self>) -> Field {
        Field::U8(grid)
    }
}

impl FieldClass for u16 {
    fn narrow(class: usize) -> Self {
        class as u16
    }
    fn field(grid: ClassGrid<Self>) -> Field {
        Field::U16(grid)
    }
}

/// Classes of an image and the subdomain of each class (class 0 is the background, `OUTSIDE`).
pub(crate) struct Classified {
    pub field: Field,
    pub subdomains: Vec<SubdomainId>,
    /// The image voxel of the field's voxel `(0, 0, 0)`: the field holds the box of the
    /// non-background voxels with a voxel of background around it (within the image).
    pub offset: [usize; 3],
}

/// The box of non-background voxels grown by one voxel within the image, as its lower corner and
/// its dimensions: outside it every voxel is background, so the class of every point is the same
/// (the domain box of the interpolation shrinks, but only by background). The whole image when
/// there is nothing but background.
fn crop_box<T: Copy + PartialEq + Sync>(
    dims: [usize; 3],
    values: &[T],
    background: T,
) -> ([usize; 3], [usize; 3]) {
    let [nx, ny, _] = dims;
    let nx = nx.max(1);
    let rows_per_task = (CHUNK / nx).max(1);
    let empty = ([usize::MAX; 3], [0usize; 3]);
    // Rows in parallel tasks; the box of several is the min and max of theirs, in any order.
    let (lo, hi) = values
        .par_chunks(rows_per_task * nx)
        .enumerate()
        .map(|(task, rows)| {
            let (mut lo, mut hi) = empty;
            for (r, values) in rows.chunks_exact(nx).enumerate() {
                let Some(first) = values.iter().position(|&c| c != background) else {
                    continue;
                };
                let last = values
                    .iter()
                    .rposition(|&c| c != background)
                    .unwrap_or(first);
                let row = task * rows_per_task + r;
                let (j, k) = (row % ny, row / ny);
                lo = [lo[0].min(first), lo[1].min(j), lo[2].min(k)];
                hi = [hi[0].max(last), hi[1].max(j), hi[2].max(k)];
            }
            (lo, hi)
        })
        .reduce(
            || empty,
            |(a, b), (c, d)| {
                (
                    std::array::from_fn(|i| a[i].min(c[i])),
                    std::array::from_fn(|i| b[i].max(d[i])),
                )
            },
        );
    if lo[0] == usize::MAX {
        return ([0; 3], dims);
    }
    let lo = [0, 1, 2].map(|a| lo[a].saturating_sub(1));
    let hi = [0, 1, 2].map(|a| (hi[a] + 1).min(dims[a] - 1));
    (lo, [0, 1, 2].map(|a| hi[a] - lo[a] + 1))
}

/// A cropped grid: the image voxel of its voxel `(0, 0, 0)`, its dimensions, its values.
type Cropped<T> = ([usize; 3], [usize; 3], Vec<T>);

/// The values of the box at `lo` of dimensions `size`, mapped by `map`, x fastest (a slice of
/// the box per parallel task).
fn extract<T: Copy + Sync, U: Copy + Default + Send>(
    dims: [usize; 3],
    values: &[T],
    (lo, size): ([usize; 3], [usize; 3]),
    map: impl Fn(T) -> U + Sync,
) -> Vec<U> {
    let [nx, ny, _] = dims;
    let mut out = vec![U::default(); size[0] * size[1] * size[2]];
    out.par_chunks_mut((size[0] * size[1]).max(1))
        .enumerate()
        .for_each(|(dk, slice)| {
            let k = lo[2] + dk;
            for (dj, row_out) in slice.chunks_exact_mut(size[0].max(1)).enumerate() {
                let row = nx * (lo[1] + dj + ny * k) + lo[0];
                for (o, &v) in row_out.iter_mut().zip(&values[row..row + size[0]]) {
                    *o = map(v);
                }
            }
        });
    out
}

/// The classes of the box of non-background voxels (see [`crop_box`]), its offset and its
/// dimensions.
fn crop<T: Copy + PartialEq + Sync + Send + Default>(
    dims: [usize; 3],
    classes: Vec<T>,
    background: T,
) -> Cropped<T> {
    let (lo, size) = crop_box(dims, &classes, background);
    if size == dims {
        return ([0; 3], dims, classes);
    }
    let out = extract(dims, &classes, (lo, size), |c| c);
    (lo, size, out)
}

/// Labels: every voxel value must be a non-negative integer; `background` is the outside. The
/// subdomain of a label is the label itself, except that with a non-zero background, label 0 (if
/// present) takes the background's number, since subdomain 0 means outside.
pub(crate) fn classify_labels(
    image: &Image,
    background: u32,
    interpolation: Interpolation,
) -> Result<Classified, ImageLabelError> {
    let n = image.voxels.len();
    let label_of = |i: usize| -> Result<u32, ImageLabelError> {
        let v = image.voxels.value(i);
        label_value(v).ok_or(ImageLabelError::NotALabel { value: v, voxel: i })
    };
    // The distinct labels, sorted: direct histograms for bytes and shorts, a sort otherwise.
    let mut present: Vec<u32> = match &image.voxels {
        Voxels::U8(v) => histogram(v, 256),
        Voxels::U16(v) => histogram(v, 65_536),
        _ => {
            let mut all = (0..n).map(label_of).collect::<Result<Vec<u32>, _>>()?;
            all.sort_unstable();
            all.dedup();
            all
        }
    };
    present.retain(|&l| l != background);
    if present.len() > MAX_LABELS {
        return Err(ImageLabelError::TooManyLabels(present.len()));
    }
    // Class 0 is the background; classes 1.. the other labels in increasing order.
    let mut labels = vec![background];
    labels.extend_from_slice(&present);
    let subdomains = labels
        .iter()
        .map(|&l| match l {
            l if l == background => OUTSIDE,
            0 => SubdomainId(background),
            l => SubdomainId(l),
        })
        .collect();
    let class_of = |l: u32| -> usize {
        if l == background {
            0
        } else {
            present.binary_search(&l).map_or(0, |c| c + 1)
        }
    };
    let count = labels.len();
    // One class per voxel of the cropped box, in the narrowest type, without a wider
    // intermediate buffer: bytes and shorts are cropped on their raw values (the background
    // label is the only value of class 0) before a table maps them, so that the voxels outside
    // the labels' box are read once.
    fn per_voxel<T: FieldClass>(
        image: &Image,
        background: u32,
        table: &dyn Fn(u32) -> usize,
        label_of: &dyn Fn(usize) -> Result<u32, ImageLabelError>,
        count: usize,
        interpolation: Interpolation,
    ) -> Result<(Field, [usize; 3]), ImageLabelError> {
        fn raw<V: Copy + PartialEq + Sync + TryFrom<u32>, T: Copy + Default + Send + Sync>(
            dims: [usize; 3],
            v: &[V],
            background: u32,
            t: &[T],
            index: fn(V) -> usize,
        ) -> Cropped<T> {
            // A background the type cannot hold: no voxel is background.
            let bx = match V::try_from(background) {
                Ok(b) => crop_box(dims, v, b),
                Err(_) => ([0; 3], dims),
            };
            (bx.0, bx.1, extract(dims, v, bx, |x| t[index(x)]))
        }
        let dims = image.dims;
        let (offset, dims, classes) = match &image.voxels {
            Voxels::U8(v) => {
                let t: Vec<T> = (0..256u32).map(|l| T::narrow(table(l))).collect();
                raw(dims, v, background, &t, usize::from)
            }
            Voxels::U16(v) => {
                let t: Vec<T> = (0..65_536u32).map(|l| T::narrow(table(l))).collect();
                raw(dims, v, background, &t, usize::from)
            }
            voxels => {
                let classes = (0..voxels.len())
                    .map(|i| label_of(i).map(|l| T::narrow(table(l))))
                    .collect::<Result<Vec<T>, _>>()?;
                crop(dims, classes, T::from(0))
            }
        };
        let grid = ClassGrid::new(dims, classes, count, interpolation);
        Ok((T::field(grid), offset))
    }
    let per_voxel = if count <= 256 {
        per_voxel::<u8>
    } else {
        per_voxel::<u16>
    };
    let (field, offset) = per_voxel(
        image,
        background,
        &class_of,
        &label_of,
        count,
        interpolation,
    )?;
    Ok(Classified {
        field,
        subdomains,
        offset,
    })
}

/// Gray levels: class 1 (subdomain 1) where the value is at least `isovalue`, else background.
pub(crate) fn classify_isovalue(
    image: &Image,
    isovalue: f64,
    interpolation: Interpolation,
) -> Classified {
    let classes: Vec<u8> = (0..image.voxels.len())
        .map(|i| u8::from(image.voxels.value(i) >= isovalue))
        .collect();
    let (offset, dims, classes) = crop(image.dims, classes, 0);
    Classified {
        field: Field::U8(ClassGrid::new(dims, classes, 2, interpolation)),
        subdomains: vec![OUTSIDE, SubdomainId(1)],
        offset,
    }
}

/// The labels present among `values` (each below `size`), sorted.
fn histogram<T: Copy + Into<usize> + Sync>(values: &[T], size: usize) -> Vec<u32> {
    let seen = values
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut seen = vec![false; size];
            for &v in chunk {
                seen[v.into()] = true;
            }
            seen
        })
        .reduce(
            || vec![false; size],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x |= y);
                a
            },
        );
    (0..size as u32).filter(|&l| seen[l as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    const DIMS: [usize; 3] = [20, 20, 3];

    /// A 20×20×3 image of labels below `labels` (0 the background) as shorts, with a voxel of
    /// background around them (324 voxels, as many distinct labels when `labels` ≥ 400),
    /// classified by [`classify_labels`].
    fn classified(labels: u16) -> (Image, Classified) {
        let [nx, ny, nz] = DIMS;
        let voxels = (0..nx * ny * nz)
            .map(|i| {
                let (x, y, z) = (i % nx, i / nx % ny, i / (nx * ny));
                let inner = (1..nx - 1).contains(&x) && (1..ny - 1).contains(&y) && z == 1;
                if inner { (i as u16 * 7) % labels } else { 0 }
            })
            .collect();
        let image = Image::axis_aligned(DIMS, DVec3::ONE, DVec3::ZERO, Voxels::U16(voxels));
        let classified = classify_labels(&image, 0, Interpolation::Nearest).unwrap();
        (image, classified)
    }

    /// The class of image voxel `v` in `grid`, whose voxel `(0, 0, 0)` is image voxel `offset`:
    /// background (0) outside the grid's box.
    fn class_in<C: Class>(grid: &ClassGrid<C>, offset: [usize; 3], v: [usize; 3]) -> u32 {
        let local: Option<Vec<usize>> = (0..3)
            .map(|a| v[a].checked_sub(offset[a]).filter(|&x| x < grid.dims[a]))
            .collect();
        local.map_or(0, |l| grid.voxel(l[0], l[1], l[2]).index())
    }

    /// Every voxel of the image keeps its label: its class in the (cropped) field is the rank
    /// of its label among the labels present, in bytes up to 256 classes and in shorts beyond.
    #[test]
    fn classes_are_label_ranks_in_the_narrowest_type() {
        for (labels, wide) in [(5, false), (255, false), (400, true)] {
            let (image, classified) = classified(labels);
            let Voxels::U16(values) = &image.voxels else {
                unreachable!()
            };
            let mut present: Vec<u16> = values.iter().copied().filter(|&l| l != 0).collect();
            present.sort_unstable();
            present.dedup();
            assert_eq!(classified.subdomains.len(), present.len() + 1);
            let o = classified.offset;
            let class = |v: [usize; 3]| match &classified.field {
                Field::U8(g) => class_in(g, o, v),
                Field::U16(g) => class_in(g, o, v),
            };
            assert_eq!(matches!(classified.field, Field::U16(_)), wide);
            for (n, &l) in values.iter().enumerate() {
                let rank = present.binary_search(&l).map_or(0, |r| r as u32 + 1);
                let v = [n % DIMS[0], n / DIMS[0] % DIMS[1], n / (DIMS[0] * DIMS[1])];
                assert_eq!(class(v), rank, "voxel {n}, label {l}");
            }
        }
    }
}

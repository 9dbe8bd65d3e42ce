//! Conflict kernels: what makes a 3D triangulation Delaunay (Euclidean in-sphere test) or regular
//! (power test on weighted points). The combinatorial engine is shared; only these predicates and
//! the per-vertex weights differ.

use crate::kernel::perturbation::{
    beyond_hull_facet_perturbed, in_sphere_perturbed, power_beyond_hull_facet_perturbed,
    power_test_perturbed,
};
use crate::kernel::power::orthocenter3;
use crate::kernel::{Point3, Sign, StaticFilter, WeightedPoint3, circumcenter3};
use std::fmt::Debug;

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Euclidean {}
    impl Sealed for super::Power {}
}

/// The predicate that decides whether a point destroys a cell, plus the per-vertex data it needs.
/// Implemented by [`Euclidean`] (Delaunay) and [`Power`] (regular); sealed.
pub trait ConflictKernel: Clone + Debug + Default + Send + Sync + sealed::Sealed {
    /// Whether vertices carry weights, and so can be hidden (a compile-time switch: the Delaunay
    /// engine carries none of the hidden-vertex bookkeeping).
    const WEIGHTED: bool;
    /// Records the weight of a new vertex.
    fn push_vertex(&mut self, weight: f64);
    /// Weight of finite vertex `v`.
    fn weight(&self, v: u32) -> f64;
    /// Whether finite vertex `v` is hidden (in no cell).
    fn is_hidden(&self, v: u32) -> bool;
    /// Marks `v` hidden.
    fn hide(&mut self, v: u32);
    /// Clears the hidden mark of `v` (before it is inserted again).
    fn unhide(&mut self, v: u32);
    /// Changes the weight of `v` (which must be in no cell).
    fn set_weight(&mut self, v: u32, weight: f64);
    /// Whether `q` conflicts with the positively oriented finite cell `v`.
    fn in_conflict_finite(
        &self,
        filter: &StaticFilter,
        points: &[Point3],
        v: [u32; 4],
        q: WeightedPoint3,
    ) -> bool;
    /// Whether `q` conflicts with the infinite cell over hull facet `tri`, where `orient` is
    /// the orientation of that cell with the infinite vertex replaced by `q`'s point.
    fn beyond_hull_facet(
        &self,
        points: &[Point3],
        tri: [u32; 3],
        orient: Sign,
        q: WeightedPoint3,
    ) -> bool;
    /// Centre of the (orthogonal) sphere of finite cell `v`.
    fn center(&self, points: &[Point3], v: [u32; 4]) -> Point3;
}

/// The Euclidean in-sphere test: Delaunay triangulations. Stores nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Euclidean;

impl ConflictKernel for Euclidean {
    const WEIGHTED: bool = false;

    #[inline]
    fn push_vertex(&mut self, _weight: f64) {}

    #[inline]
    fn weight(&self, _v: u32) -> f64 {
        0.0
    }

    #[inline]
    fn is_hidden(&self, _v: u32) -> bool {
        false
    }

    #[inline]
    fn hide(&mut self, _v: u32) {}

    #[inline]
    fn unhide(&mut self, _v: u32) {}

    #[inline]
    fn set_weight(&mut self, _v: u32, _weight: f64) {}

    #[inline]
    fn in_conflict_finite(
        &self,
        filter: &StaticFilter,
        points: &[Point3],
        v: [u32; 4],
        q: WeightedPoint3,
    ) -> bool {
        let p = q.point;
        let (a, b, c, d) = (
            points[v[0] as usize],
            points[v[1] as usize],
            points[v[2] as usize],
            points[v[3] as usize],
        );
        match filter.insphere_static(a, b, c, d, p) {
            Some(s) => s == Sign::Positive,
            None => in_sphere_refined(filter, [a, b, c, d], p),
        }
    }

    #[inline]
    fn beyond_hull_facet(
        &self,
        points: &[Point3],
        tri: [u32; 3],
        orient: Sign,
        q: WeightedPoint3,
    ) -> bool {
        beyond_hull_facet_perturbed(tri.map(|v| points[v as usize]), orient, q.point)
    }

    fn center(&self, points: &[Point3], v: [u32; 4]) -> Point3 {
        let [a, b, c, d] = v.map(|w| points[w as usize]);
        circumcenter3(a, b, c, d)
    }
}

/// The in-sphere test when the static filter cannot decide.
#[cold]
#[inline(never)]
fn in_sphere_refined(filter: &StaticFilter, q: [Point3; 4], p: Point3) -> bool {
    match filter.insphere(q[0], q[1], q[2], q[3], p) {
        Sign::Positive => true,
        Sign::Negative => false,
        Sign::Zero => in_sphere_perturbed(q, p),
    }
}

/// The power test on weighted points: regular (weighted Delaunay) triangulations.
#[derive(Clone, Debug, Default)]
pub struct Power {
    weights: Vec<f64>,
    hidden: Vec<bool>,
}

impl Power {
    fn weighted(&self, points: &[Point3], v: u32) -> WeightedPoint3 {
        WeightedPoint3::new(points[v as usize], self.weights[v as usize])
    }

    /// Weights and hidden flags, for the checker's tests to corrupt.
    #[cfg(test)]
    pub(super) fn state_mut(&mut self) -> (&mut Vec<f64>, &mut Vec<bool>) {
        (&mut self.weights, &mut self.hidden)
    }
}

impl ConflictKernel for Power {
    const WEIGHTED: bool = true;

    fn push_vertex(&mut self, weight: f64) {
        self.weights.push(weight);
        self.hidden.push(false);
    }

    fn weight(&self, v: u32) -> f64 {
        self.weights[v as usize]
    }

    fn is_hidden(&self, v: u32) -> bool {
        self.hidden.get(v as usize).copied().unwrap_or(false)
    }

    fn hide(&mut self, v: u32) {
        self.hidden[v as usize] = true;
    }

    fn unhide(&mut self, v: u32) {
        self.hidden[v as usize] = false;
    }

    fn set_weight(&mut self, v: u32, weight: f64) {
        self.weights[v as usize] = weight;
    }

    fn in_conflict_finite(
        &self,
        _filter: &StaticFilter,
        points: &[Point3],
        v: [u32; 4],
        q: WeightedPoint3,
    ) -> bool {
        power_test_perturbed(v.map(|x| self.weighted(points, x)), q)
    }

    fn beyond_hull_facet(
        &self,
        points: &[Point3],
        tri: [u32; 3],
        orient: Sign,
        q: WeightedPoint3,
    ) -> bool {
        power_beyond_hull_facet_perturbed(tri.map(|x| self.weighted(points, x)), orient, q)
    }

    fn center(&self, points: &[Point3], v: [u32; 4]) -> Point3 {
        let [a, b, c, d] = v.map(|x| self.weighted(points, x));
        orthocenter3(a, b, c, d)
    }
}

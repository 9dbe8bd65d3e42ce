//! Delaunay refinement: the `MesherLevel` trait, the engine that stacks levels, criteria.

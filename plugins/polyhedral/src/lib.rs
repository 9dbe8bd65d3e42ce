//! Oracle over closed triangle surfaces: AABB tree, segment hits, inside test.

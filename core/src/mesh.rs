//! Mesh data model shared by formats, plugins and the mesher: surfaces, tet meshes, images.

//! The `Oracle` trait: everything a mesher may ask of a domain.

//! Fuzzes the NIfTI-1 image reader: any input must give an image or an error, never a panic, a
//! hang or an allocation sized by the header's dimensions before they are checked against the data.
#![no_main]

use delamesh_formats::image::{ImageFormat, read_image_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(image) = read_image_bytes(data, ImageFormat::Nifti, None) {
        let _ = image.validate();
    }
});

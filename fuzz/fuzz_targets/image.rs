//! libFuzzer target: `mirador_fuzz::image` (see fuzz/README.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mirador_fuzz::image(data));

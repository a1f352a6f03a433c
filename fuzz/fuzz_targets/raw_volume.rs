//! libFuzzer target: `mirador_fuzz::raw_volume` (see fuzz/README.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mirador_fuzz::raw_volume(data));

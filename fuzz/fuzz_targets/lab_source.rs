//! libFuzzer target: `mirador_fuzz::lab_source` (see fuzz/README.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mirador_fuzz::lab_source(data));

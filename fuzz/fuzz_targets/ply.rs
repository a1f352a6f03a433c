//! libFuzzer target: `mirador_fuzz::ply` (see fuzz/README.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mirador_fuzz::ply(data));

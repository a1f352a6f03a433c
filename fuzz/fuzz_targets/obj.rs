//! libFuzzer target: `mirador_fuzz::obj` (see fuzz/README.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mirador_fuzz::obj(data));

//! libFuzzer target: `mirador_fuzz::scene_toml` (see fuzz/README.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mirador_fuzz::scene_toml(data));

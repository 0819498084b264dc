//! Sets `cfg(reachc_avx512)` when the tests of the AVX-512 lanes can run here: the machine
//! building the crate (where `cargo test` runs it) has AVX-512 F and DQ and is the target, or
//! `REACHC_REQUIRE_AVX512=1` asks for them regardless (they then fail on a processor without).
//! Without it those tests are ignored, a skip `cargo test` shows, rather than passes that test
//! nothing. Only tests read the cfg: the library is the same either way.

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=REACHC_REQUIRE_AVX512");
    println!("cargo::rustc-check-cfg=cfg(reachc_avx512)");
    let required = std::env::var_os("REACHC_REQUIRE_AVX512").is_some_and(|v| v == "1");
    if required || host_has_avx512() {
        println!("cargo::rustc-cfg=reachc_avx512");
    }
}

/// Whether this machine has AVX-512 F and DQ and builds for itself.
fn host_has_avx512() -> bool {
    let native = std::env::var("HOST").ok() == std::env::var("TARGET").ok();
    #[cfg(target_arch = "x86_64")]
    {
        native
            && std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512dq")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = native;
        false
    }
}

//! Including code that `reachc_compiler::Config` generated in a build script.

/// Includes the Rust code generated for a spec by `reachc_compiler::Config::compile` in `build.rs`:
/// `$OUT_DIR/<name>.rs`, where `name` is the model's crate name with `-` written `_`.
///
/// The file holds items only (the model's `System` type and `info()`), so it can be included in
/// any module:
///
/// ```ignore
/// mod pendulum {
///     reachc_runtime::include_sde!("pendulum");
/// }
/// ```
#[macro_export]
macro_rules! include_sde {
    ($name:literal) => {
        include!(concat!(env!("OUT_DIR"), "/", $name, ".rs"));
    };
}

//! The models and metrics the unit tests of the constants share.

use std::path::Path;

use crate::analysis::Derivatives;
use crate::driver::check_source;
use crate::model::Model;

pub(crate) fn model_of(src: &str) -> (Model, Derivatives) {
    let (model, diags) = check_source(src, Path::new("."));
    let mut model = model.unwrap_or_else(|| panic!("spec does not check: {diags:?}"));
    let d = Derivatives::of(&mut model);
    (model, d)
}

pub(super) fn spec(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../specs")
        .join(name);
    std::fs::read_to_string(path).unwrap()
}

pub(super) const PAPER_P: [f64; 4] = [35.68, 2.21, 2.21, 1.27];

pub(super) fn identity(n: usize) -> Vec<f64> {
    let mut id = vec![0.0; n * n];
    for i in 0..n {
        id[i * n + i] = 1.0;
    }
    id
}

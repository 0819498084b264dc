//! The values mutations put into specs: extremes of numbers, odd names, nesting depths,
//! analysis keys with values, whole lines at the language's limits.

/// Numbers a mutation puts in place of a literal: boundaries of f64 and of integer types.
pub const EXTREMES: &[&str] = &[
    "0",
    "1",
    "-1",
    "0.0",
    "-0",
    "0.5",
    "1e308",
    "1.7976931348623157e308",
    "1e309",
    "1e-308",
    "1e-300",
    "5e-324",
    "1e-320",
    "1e-9",
    "1e6",
    "1e9",
    "1e15",
    "1e18",
    "100000",
    "2147483647",
    "2147483648",
    "4294967296",
    "9007199254740993",
    "18446744073709551616",
    "99999999999999999999999999999",
];

/// Names an identifier is renamed to: built-ins, keywords, Rust words, invalid and odd names.
pub const NAMES: &[&str] = &[
    "t", "pi", "e", "inf", "nan", "model", "state", "for", "in", "drift", "analysis", "x", "w",
    "_", "self", "Self", "crate", "fn", "main", "std", "r#x", "θ", "x0", "ref",
];

/// How deep a nesting mutation wraps a token in parentheses (the parser's limit is 200).
pub const DEPTHS: &[usize] = &[1, 20, 199, 200, 201, 1000, 100_000];

/// Factors a matrix mutation multiplies every entry by.
pub const SCALES: &[&str] = &["1e300", "1e-300", "1e154", "-1", "0"];

/// Ranges of the loops a `for` mutation wraps around a loop.
pub const LOOP_ENDS: &[&str] = &["2", "10", "1000", "1e9"];

/// Analysis keys and values to give them (some valid for the key, some for another key).
pub const ANALYSIS: &[(&str, &[&str])] = &[
    ("method", &["contraction", "interval", "euler"]),
    ("delta", &["0", "1", "1e-300", "0.999999", "1e-15", "0.5"]),
    (
        "horizon",
        &["1e6", "1e9", "1e-300", "1e308", "0.001", "100"],
    ),
    (
        "step",
        &["1e-300", "1e-6", "1e-3", "1e308", "0.5", "horizon"],
    ),
    (
        "metric",
        &[
            "identity",
            "auto",
            "auto(states = [x])",
            "[[1e300]]",
            "[[1, 0], [0, 1]]",
            "[]",
        ],
    ),
    (
        "radius",
        &[
            "amgf",
            "paper(eps = 1/16)",
            "paper(optimal)",
            "paper(eps = 1e-300)",
            "paper()",
        ],
    ),
    (
        "rate",
        &[
            "local",
            "global",
            "empirical(paths = 2)",
            "empirical(paths = 20000)",
            "empirical",
        ],
    ),
    ("inclusion", &["natural", "jacobian", "mixed"]),
    ("integrator", &["validated", "rk4", "euler"]),
    ("guarantee", &["uniform", "pointwise"]),
    (
        "transform",
        &[
            "auto",
            "[[0]]",
            "[[1, 0], [0, 1]]",
            "[[1, 1], [1, 1]]",
            "[[1e300]]",
        ],
    ),
    ("outputs", &["[]", "[t]", "[x]"]),
];

/// Whole lines a mutation inserts: declarations at and beyond the language's limits.
pub const LINES: &[&str] = &[
    "state big[1..1000000] = 0",
    "noise many[1..100000]",
    "const N = 1e308",
    "noise r#x",
    "input u in [1e308, -1e308]",
    "table fz = csv(\"/dev/null\")",
    "let fz = fz",
    "domain { }",
    "model again",
];

//! Turning spec names into Rust identifiers: the model's struct and the Cargo package name of
//! its generated crate, and the index constants of its states, inputs and noise channels.
//!
//! These are the only spec names that become Rust identifiers; everything else (table names,
//! doc comments) only appears inside string literals and doc comments. The results here are
//! always valid: ASCII letters, digits, `_` / `-` only, never empty, never starting with a
//! digit, never a Rust keyword or a name the generated code (or Cargo) relies on.

use std::collections::BTreeSet;

/// Rust keywords (strict, reserved and weak ones that are keywords in some position), lowercase.
const KEYWORDS: &[&str] = &[
    "abstract", "as", "async", "await", "become", "box", "break", "const", "continue", "crate",
    "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if", "impl",
    "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub", "ref",
    "return", "self", "static", "struct", "super", "trait", "true", "try", "type", "typeof",
    "union", "unsafe", "unsized", "use", "virtual", "where", "while", "yield",
];

/// Type names the generated code refers to unqualified, or that would shadow the prelude: a
/// model struct with one of these names gets the suffix `Model`.
const RESERVED_TYPES: &[&str] = &[
    "Self",
    "Interval",
    "System",
    "ModelInfo",
    "Option",
    "Some",
    "None",
    "Result",
    "Ok",
    "Err",
    "String",
    "Vec",
    "Box",
    "ToString",
    "ToOwned",
    "Clone",
    "Copy",
    "Send",
    "Sync",
    "Sized",
    "Unpin",
    "Drop",
    "Fn",
    "FnMut",
    "FnOnce",
    "AsyncFn",
    "AsyncFnMut",
    "AsyncFnOnce",
    "Default",
    "Debug",
    "Hash",
    "Iterator",
    "IntoIterator",
    "DoubleEndedIterator",
    "ExactSizeIterator",
    "Extend",
    "FromIterator",
    "AsRef",
    "AsMut",
    "Into",
    "From",
    "TryFrom",
    "TryInto",
    "PartialEq",
    "Eq",
    "PartialOrd",
    "Ord",
];

/// Package names Cargo rejects (or warns about) besides keywords: its own directory names,
/// the standard crates and Windows device names.
const RESERVED_CRATES: &[&str] = &[
    "build",
    "deps",
    "examples",
    "incremental",
    "std",
    "core",
    "alloc",
    "proc-macro",
    "proc_macro",
    "test",
    "con",
    "prn",
    "aux",
    "nul",
    "com1",
    "com2",
    "com3",
    "com4",
    "com5",
    "com6",
    "com7",
    "com8",
    "com9",
    "lpt1",
    "lpt2",
    "lpt3",
    "lpt4",
    "lpt5",
    "lpt6",
    "lpt7",
    "lpt8",
    "lpt9",
    "reachc",
    "reachc-runtime",
    "reachc-core",
    "reachc-compiler",
];

/// Splits a name into ASCII alphanumeric words: at every other character (`_`, `-`, spaces,
/// non-ASCII, punctuation) and at lower-to-upper case changes (`vanDerPol` -> van, Der, Pol).
fn words(name: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut cur = String::new();
    let mut prev_lower_or_digit = false;
    for ch in name.chars() {
        if !ch.is_ascii_alphanumeric() {
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
            prev_lower_or_digit = false;
            continue;
        }
        if ch.is_ascii_uppercase() && prev_lower_or_digit && !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
        prev_lower_or_digit = ch.is_ascii_lowercase() || ch.is_ascii_digit();
        cur.push(ch);
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// The Rust type name of a model's struct: the name in UpperCamelCase (`van_der_pol` ->
/// `VanDerPol`, `chain10` -> `Chain10`), keeping only ASCII letters and digits. A name that
/// is empty, starts with a digit, or clashes with a keyword or a prelude / runtime type name
/// gets `Model` added (`3d` -> `Model3d`, `self` -> `SelfModel`, `some` -> `SomeModel`).
pub fn type_name(model_name: &str) -> String {
    let mut name: String = words(model_name)
        .iter()
        .map(|w| {
            let mut cs = w.chars();
            let first = cs.next().map(|c| c.to_ascii_uppercase());
            first.into_iter().chain(cs).collect::<String>()
        })
        .collect();
    if name.is_empty() || name.starts_with(|c: char| c.is_ascii_digit()) {
        name.insert_str(0, "Model");
    }
    if RESERVED_TYPES.contains(&name.as_str()) || KEYWORDS.contains(&name.as_str()) {
        name.push_str("Model");
    }
    name
}

/// The Cargo package name of a model's generated crate: lowercase words joined by `-`
/// (`van_der_pol` -> `van-der-pol`, `VanDerPol` -> `van-der-pol`). A name that is empty,
/// starts with a digit, or is a Rust keyword or a name Cargo reserves gets the prefix
/// `model-` (`3d` -> `model-3d`, `fn` -> `model-fn`). A name longer than [`MAX_CRATE_NAME`]
/// bytes is cut and ends with a hash of the model's name.
pub fn crate_name(model_name: &str) -> String {
    bounded(model_name, unbounded_crate_name(model_name))
}

/// The longest crate name: it names the cached crate's directory, the binary and cargo's
/// files (`<name>-<16 hex>.d`), each at most 255 bytes on common file systems.
pub const MAX_CRATE_NAME: usize = 64;

/// `name` if it has at most [`MAX_CRATE_NAME`] bytes; otherwise its first 47 bytes and 16 hex
/// digits of the SHA-256 of `model_name`, so that distinct long model names stay distinct.
fn bounded(model_name: &str, name: String) -> String {
    if name.len() <= MAX_CRATE_NAME {
        return name;
    }
    let mut hash = crate::package::sha256::Sha256::new();
    hash.update(model_name.as_bytes());
    let hex = hash.finish_hex();
    let cut = name.char_indices().nth(47).map_or(name.len(), |(i, _)| i);
    format!("{}-{}", name[..cut].trim_end_matches('-'), &hex[..16])
}

fn unbounded_crate_name(model_name: &str) -> String {
    let name = words(model_name)
        .iter()
        .map(|w| w.to_ascii_lowercase())
        .collect::<Vec<_>>()
        .join("-");
    let needs_prefix = name.is_empty()
        || name.starts_with(|c: char| c.is_ascii_digit())
        || KEYWORDS.contains(&name.replace('-', "_").as_str())
        || RESERVED_CRATES.contains(&name.as_str());
    if needs_prefix {
        if name.is_empty() {
            "model".to_string()
        } else {
            format!("model-{name}")
        }
    } else {
        name
    }
}

/// The Rust identifier of a crate called `crate_name` (`-` becomes `_`), as written in
/// `use` paths.
pub fn crate_ident(crate_name: &str) -> String {
    crate_name.replace('-', "_")
}

/// The names of constants for a list of spec names (the states, inputs or noise channels of a
/// model), in order: each in SCREAMING_SNAKE_CASE (`theta` -> `THETA`, `x[3]` -> `X_3`,
/// `vanDerPol` -> `VAN_DER_POL`); a name without ASCII letters or digits becomes `fallback`, one
/// starting with a digit gets the prefix `fallback_`. Upper case, they are never keywords.
///
/// Names equal after this keep the plain form for their first occurrence; the others get the
/// first suffix `_2`, `_3`, ... that no other name uses (`a_b`, `aB` -> `A_B`, `A_B_2`), so
/// the results are distinct, and depend only on the list.
///
/// `fallback` must be an upper-case identifier (`STATE`).
pub fn const_names(names: &[String], fallback: &str) -> Vec<String> {
    let bases: Vec<String> = names
        .iter()
        .map(|name| {
            let base = words(name)
                .iter()
                .map(|w| w.to_ascii_uppercase())
                .collect::<Vec<_>>()
                .join("_");
            if base.is_empty() {
                fallback.to_string()
            } else if base.starts_with(|c: char| c.is_ascii_digit()) {
                format!("{fallback}_{base}")
            } else {
                base
            }
        })
        .collect();
    // Every plain form is reserved, so a suffixed name never takes a later name's plain form.
    let mut taken: BTreeSet<String> = bases.iter().cloned().collect();
    let mut seen: BTreeSet<&str> = BTreeSet::new();
    bases
        .iter()
        .map(|base| {
            if seen.insert(base) {
                return base.clone();
            }
            let name = (2..)
                .map(|k| format!("{base}_{k}"))
                .find(|candidate| !taken.contains(candidate))
                .expect("some suffix is free");
            taken.insert(name.clone());
            name
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn is_ident(s: &str) -> bool {
        syn::parse_str::<syn::Ident>(s).is_ok()
    }

    #[test]
    fn type_names() {
        assert_eq!(type_name("pendulum"), "Pendulum");
        assert_eq!(type_name("van_der_pol"), "VanDerPol");
        assert_eq!(type_name("vanDerPol"), "VanDerPol");
        assert_eq!(type_name("chain10"), "Chain10");
        assert_eq!(type_name("linear_n"), "LinearN");
        assert_eq!(type_name("3d"), "Model3d");
        assert_eq!(type_name(""), "Model");
        assert_eq!(type_name("_"), "Model");
        assert_eq!(type_name("self"), "SelfModel");
        assert_eq!(type_name("Self"), "SelfModel");
        assert_eq!(type_name("some"), "SomeModel");
        assert_eq!(type_name("string"), "StringModel");
        assert_eq!(type_name("interval"), "IntervalModel");
        assert_eq!(type_name("fn"), "Fn".to_string() + "Model");
        assert_eq!(type_name("} fn evil() {"), "FnEvil");
        assert_eq!(type_name("pénd ulum"), "PNdUlum");
    }

    #[test]
    fn crate_names() {
        assert_eq!(crate_name("pendulum"), "pendulum");
        assert_eq!(crate_name("van_der_pol"), "van-der-pol");
        assert_eq!(crate_name("VanDerPol"), "van-der-pol");
        assert_eq!(crate_name("chain1000"), "chain1000");
        assert_eq!(crate_name("3d"), "model-3d");
        assert_eq!(crate_name("fn"), "model-fn");
        assert_eq!(crate_name("type"), "model-type");
        assert_eq!(crate_name("test"), "model-test");
        assert_eq!(crate_name("build"), "model-build");
        assert_eq!(crate_name(""), "model");
        assert_eq!(crate_name("**"), "model");
        // Long names are cut and hashed: at most 64 bytes, distinct names stay distinct.
        let long_a = "a".repeat(300);
        let long_b = format!("{}b", "a".repeat(299));
        let (a, b) = (crate_name(&long_a), crate_name(&long_b));
        assert_eq!(a.len(), 64);
        assert!(
            a.starts_with(&"a".repeat(47)) && a.as_bytes()[47] == b'-',
            "{a}"
        );
        assert_ne!(a, b);
        assert_eq!(b.len(), 64);
        assert_eq!(crate_name(&"a".repeat(64)), "a".repeat(64));
        assert_eq!(crate_ident("van-der-pol"), "van_der_pol");
    }

    fn consts(names: &[&str]) -> Vec<String> {
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        const_names(&names, "STATE")
    }

    #[test]
    fn const_names_are_screaming_snake_case() {
        assert_eq!(consts(&["theta", "omega"]), ["THETA", "OMEGA"]);
        assert_eq!(
            consts(&["x[3]", "vanDerPol", "x_10", "self", "type"]),
            ["X_3", "VAN_DER_POL", "X_10", "SELF", "TYPE"]
        );
        assert_eq!(consts(&["_", "3d", "__"]), ["STATE", "STATE_3D", "STATE_2"]);
    }

    #[test]
    fn clashing_const_names_get_distinct_suffixes() {
        assert_eq!(consts(&["a_b", "aB", "a__b"]), ["A_B", "A_B_2", "A_B_3"]);
        // A suffix never takes another name's plain form, wherever it comes in the list.
        assert_eq!(
            consts(&["x[1]", "x_1", "x_1_2", "x1_2"]),
            ["X_1", "X_1_3", "X_1_2", "X1_2"]
        );
        assert_eq!(consts(&["x_1_2", "x[1]", "x_1"]), ["X_1_2", "X_1", "X_1_3"]);
        let names: Vec<String> = (0..50).map(|i| format!("x{}", "_".repeat(i % 3))).collect();
        let out = const_names(&names, "STATE");
        let distinct: BTreeSet<&String> = out.iter().collect();
        assert_eq!(distinct.len(), out.len());
        assert!(out.iter().all(|c| is_ident(c)));
    }

    #[test]
    fn always_valid_identifiers() {
        let names = [
            "",
            "_",
            "self",
            "Self",
            "crate",
            "super",
            "fn",
            "type",
            "r#x",
            "} fn evil() {",
            "0",
            "9lives",
            "a-b",
            "__x__",
            "ÄÖÜ",
            "x y z",
            "unsafe",
            "union",
            "async",
        ];
        for n in names {
            let t = type_name(n);
            assert!(is_ident(&t), "type_name({n:?}) = {t:?}");
            let c = crate_ident(&crate_name(n));
            assert!(is_ident(&c), "crate_name({n:?}) = {c:?}");
            assert!(!t.is_empty() && !c.is_empty());
        }
    }
}

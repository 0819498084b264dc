//! The `Cargo.lock` of a generated crate, cut from the lock of the workspace reachc was built in
//! (embedded, see [`super::embedded::workspace_lock`]): the runtime's dependencies at the
//! versions reachc was tested with, so cargo resolves nothing from the registry and the crate
//! builds with `--locked`.
//!
//! The workspace lock lists every package of reachc's workspace; a generated crate needs the
//! runtime, the core and what they depend on. Their own entries list dev-dependencies too, which
//! a generated crate does not build (the embedded manifests have none): those are dropped
//! following the embedded manifests. The result is what cargo itself would write (same entries,
//! order and dependency spelling), so cargo leaves it as it is.

use std::cmp::Ordering;
use std::collections::BTreeSet;

use super::embedded::{runtime_files, CORE_CRATE, RUNTIME_CRATE};

/// One `[[package]]` entry.
#[derive(Clone, Debug)]
struct Package {
    name: String,
    version: String,
    source: Option<String>,
    /// The other `key = value` lines (checksum), in order.
    other: Vec<String>,
    /// Dependencies as written (`name`, `name version` or `name version (source)`).
    deps: Vec<String>,
}

/// The value of a `key = "value"` line.
fn string_value<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    let rest = line
        .strip_prefix(key)?
        .trim_start()
        .strip_prefix('=')?
        .trim();
    rest.strip_prefix('"')?.strip_suffix('"')
}

/// Parses a lock file: its header (comments, `version = N`) and its packages. `None` if it
/// does not look like a lock file.
fn parse(lock: &str) -> Option<(String, Vec<Package>)> {
    let mut header = String::new();
    let mut packages: Vec<Package> = Vec::new();
    // Some(true): inside a [[package]]; Some(false): inside another table (ignored).
    let mut in_package: Option<bool> = None;
    let mut in_deps = false;
    for line in lock.lines() {
        let t = line.trim();
        if in_deps {
            if t == "]" {
                in_deps = false;
            } else if let Some(dep) = t.trim_end_matches(',').strip_prefix('"') {
                packages
                    .last_mut()?
                    .deps
                    .push(dep.strip_suffix('"')?.to_string());
            }
            continue;
        }
        if t.starts_with('[') {
            in_package = Some(t == "[[package]]");
            if t == "[[package]]" {
                packages.push(Package {
                    name: String::new(),
                    version: String::new(),
                    source: None,
                    other: Vec::new(),
                    deps: Vec::new(),
                });
            }
            continue;
        }
        match in_package {
            None => {
                header.push_str(line);
                header.push('\n');
            }
            Some(false) => {}
            Some(true) => {
                if t.is_empty() {
                    continue;
                }
                let p = packages.last_mut()?;
                if let Some(v) = string_value(t, "name") {
                    p.name = v.to_string();
                } else if let Some(v) = string_value(t, "version") {
                    p.version = v.to_string();
                } else if let Some(v) = string_value(t, "source") {
                    p.source = Some(v.to_string());
                } else if t.starts_with("dependencies") {
                    in_deps = !t.ends_with(']');
                } else {
                    p.other.push(t.to_string());
                }
            }
        }
    }
    let ok = !packages.is_empty() && packages.iter().all(|p| !p.name.is_empty());
    ok.then(|| (header.trim_end().to_string() + "\n", packages))
}

/// The index of the package a dependency string names, if exactly one matches.
fn resolve(packages: &[Package], dep: &str) -> Option<usize> {
    let mut words = dep.splitn(3, ' ');
    let name = words.next()?;
    let version = words.next();
    let source = words
        .next()
        .map(|s| s.trim_start_matches('(').trim_end_matches(')'));
    let mut found = packages.iter().enumerate().filter(|(_, p)| {
        p.name == name
            && version.is_none_or(|v| p.version == v)
            && source.is_none_or(|s| p.source.as_deref() == Some(s))
    });
    let first = found.next()?.0;
    found.next().is_none().then_some(first)
}

/// The package names the embedded manifest of `krate` depends on (normal and build
/// dependencies, any target), following `package = "..."` renames.
fn manifest_dependencies(krate: &str) -> BTreeSet<String> {
    let path = format!("{krate}/Cargo.toml");
    let Some(file) = runtime_files().find(|f| f.path == path) else {
        return BTreeSet::new();
    };
    let text = String::from_utf8_lossy(file.bytes);
    let mut names = BTreeSet::new();
    // Some(None): a dependencies table; Some(Some(name)): a `[dependencies.name]` table.
    let mut table: Option<Option<String>> = None;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            let header = t.trim_matches(|c| c == '[' || c == ']').trim();
            let parts: Vec<&str> = header.split('.').map(str::trim).collect();
            table = parts
                .iter()
                .position(|p| *p == "dependencies" || *p == "build-dependencies")
                .map(|i| parts.get(i + 1).map(|n| n.trim_matches('"').to_string()));
            if let Some(Some(name)) = &table {
                names.insert(name.clone());
            }
            continue;
        }
        match &table {
            Some(None) => {
                if let Some((key, value)) = t.split_once('=') {
                    let key = key.trim().trim_matches('"');
                    if key.is_empty() || key.starts_with('#') {
                        continue;
                    }
                    let renamed = value.split_once("package").and_then(|(_, rest)| {
                        let rest = rest.trim_start().strip_prefix('=')?.trim_start();
                        rest.strip_prefix('"')?.split('"').next()
                    });
                    names.insert(renamed.unwrap_or(key).to_string());
                }
            }
            Some(Some(name)) => {
                if let Some(v) = string_value(t, "package") {
                    names.remove(name);
                    names.insert(v.to_string());
                }
            }
            None => {}
        }
    }
    names
}

/// semver order of two version strings (numeric major.minor.patch, then a pre-release sorts
/// before the release).
fn version_cmp(a: &str, b: &str) -> Ordering {
    let split = |v: &str| -> (Vec<u64>, Option<String>) {
        let (core, pre) = match v.split_once('-') {
            Some((c, p)) => (c, Some(p.to_string())),
            None => (v, None),
        };
        let core = core.split('+').next().unwrap_or(core);
        (
            core.split('.').map(|n| n.parse().unwrap_or(0)).collect(),
            pre,
        )
    };
    let (ca, pa) = split(a);
    let (cb, pb) = split(b);
    ca.cmp(&cb).then_with(|| match (pa, pb) {
        (None, None) => Ordering::Equal,
        (None, Some(_)) => Ordering::Greater,
        (Some(_), None) => Ordering::Less,
        (Some(x), Some(y)) => x.cmp(&y),
    })
}

/// The lock of a generated crate named `crate_name` (version 0.1.0, depending on
/// `reachc-runtime` only), cut from the workspace lock `workspace`. `None` when `workspace` is
/// not a lock file with the runtime in it (cargo then resolves from the registry).
pub fn crate_lock(workspace: &str, crate_name: &str) -> Option<String> {
    let (header, mut packages) = parse(workspace)?;
    // The runtime crates as embedded: their dev-dependencies are gone.
    for krate in [CORE_CRATE, RUNTIME_CRATE] {
        let keep = manifest_dependencies(krate);
        let i = packages
            .iter()
            .position(|p| p.name == krate && p.source.is_none())?;
        packages[i]
            .deps
            .retain(|d| keep.contains(d.split(' ').next().unwrap_or(d)));
    }
    // Everything reachable from the runtime.
    let runtime = packages
        .iter()
        .position(|p| p.name == RUNTIME_CRATE && p.source.is_none())?;
    let mut keep = vec![false; packages.len()];
    let mut stack = vec![runtime];
    while let Some(i) = stack.pop() {
        if std::mem::replace(&mut keep[i], true) {
            continue;
        }
        for dep in &packages[i].deps {
            stack.push(resolve(&packages, dep)?);
        }
    }
    // Dependencies as indices into the kept packages, before spelling them again.
    let mut kept: Vec<(Package, Vec<usize>)> = Vec::new();
    let mut index = vec![usize::MAX; packages.len()];
    for (i, p) in packages.iter().enumerate().filter(|(i, _)| keep[*i]) {
        index[i] = kept.len();
        kept.push((p.clone(), Vec::new()));
    }
    for (i, p) in packages.iter().enumerate().filter(|(i, _)| keep[*i]) {
        let deps = p
            .deps
            .iter()
            .map(|d| resolve(&packages, d).map(|j| index[j]))
            .collect::<Option<Vec<usize>>>()?;
        kept[index[i]].1 = deps;
    }
    let root = Package {
        name: crate_name.to_string(),
        version: "0.1.0".to_string(),
        source: None,
        other: Vec::new(),
        deps: Vec::new(),
    };
    kept.push((root, vec![index[runtime]]));

    // cargo's spelling: the name alone when it is unique in the lock, else with the version,
    // else with the source too.
    let spell = |j: usize| -> String {
        let p = &kept[j].0;
        let same_name = kept.iter().filter(|(q, _)| q.name == p.name).count();
        let same_version = kept
            .iter()
            .filter(|(q, _)| q.name == p.name && q.version == p.version)
            .count();
        match (same_name, same_version, &p.source) {
            (1, _, _) => p.name.clone(),
            (_, 1, _) | (_, _, None) => format!("{} {}", p.name, p.version),
            (_, _, Some(s)) => format!("{} {} ({s})", p.name, p.version),
        }
    };
    let mut entries: Vec<(&Package, Vec<String>)> = kept
        .iter()
        .map(|(p, deps)| {
            let mut spelled: Vec<String> = deps.iter().map(|&j| spell(j)).collect();
            spelled.sort();
            spelled.dedup();
            (p, spelled)
        })
        .collect();
    entries.sort_by(|(a, _), (b, _)| {
        a.name
            .cmp(&b.name)
            .then_with(|| version_cmp(&a.version, &b.version))
            .then_with(|| a.source.cmp(&b.source))
    });

    let mut out = header;
    for (p, deps) in entries {
        out.push_str("\n[[package]]\n");
        out.push_str(&format!("name = \"{}\"\n", p.name));
        out.push_str(&format!("version = \"{}\"\n", p.version));
        if let Some(source) = &p.source {
            out.push_str(&format!("source = \"{source}\"\n"));
        }
        for line in &p.other {
            out.push_str(line);
            out.push('\n');
        }
        if !deps.is_empty() {
            out.push_str("dependencies = [\n");
            for d in deps {
                out.push_str(&format!(" \"{d}\",\n"));
            }
            out.push_str("]\n");
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::package::embedded::workspace_lock;

    #[test]
    fn the_generated_lock_holds_the_runtime_and_its_dependencies_only() {
        let lock = crate_lock(workspace_lock(), "pendulum").unwrap();
        assert!(lock.starts_with("# This file is automatically @generated by Cargo."));
        let (_, packages) = parse(&lock).unwrap();
        let names: Vec<&str> = packages.iter().map(|p| p.name.as_str()).collect();
        for name in [
            "pendulum",
            "reachc-runtime",
            "reachc-core",
            "serde",
            "serde_json",
        ] {
            assert!(names.contains(&name), "{name} missing:\n{lock}");
        }
        // Neither reachc's own crates nor the runtime's dev-dependencies.
        for name in [
            "reachc",
            "reachc-compiler",
            "clap",
            "proptest",
            "divan",
            "nom",
        ] {
            assert!(!names.contains(&name), "{name} kept:\n{lock}");
        }
        let root = packages.iter().find(|p| p.name == "pendulum").unwrap();
        assert_eq!(root.deps, ["reachc-runtime"]);
        // Every dependency resolves to one entry; entries are sorted.
        for p in &packages {
            for d in &p.deps {
                assert!(resolve(&packages, d).is_some(), "{d}");
            }
        }
        assert!(names.windows(2).all(|w| w[0] <= w[1]), "{names:?}");
        // Deterministic.
        assert_eq!(crate_lock(workspace_lock(), "pendulum").unwrap(), lock);
    }

    #[test]
    fn dependency_spelling_follows_cargo() {
        let lock = "version = 4\n\n\
            [[package]]\nname = \"reachc-runtime\"\nversion = \"0.1.0\"\ndependencies = [\n \"reachc-core\",\n \"serde\",\n]\n\n\
            [[package]]\nname = \"reachc-core\"\nversion = \"0.1.0\"\ndependencies = [\n \"serde\",\n \"proptest\",\n]\n\n\
            [[package]]\nname = \"proptest\"\nversion = \"1.0.0\"\nsource = \"registry+x\"\nchecksum = \"ab\"\n\n\
            [[package]]\nname = \"serde\"\nversion = \"1.0.10\"\nsource = \"registry+x\"\nchecksum = \"cd\"\n";
        // A crate named like one of the dependencies: both are spelled with their version.
        let out = crate_lock(lock, "serde").unwrap();
        assert!(out.contains(
            "name = \"reachc-runtime\"\nversion = \"0.1.0\"\ndependencies = [\n \"reachc-core\",\n \"serde 1.0.10\",\n]\n"
        ), "{out}");
        assert!(out.contains("name = \"serde\"\nversion = \"0.1.0\"\ndependencies = [\n \"reachc-runtime\",\n]\n"), "{out}");
        assert!(!out.contains("proptest"), "{out}");
        // 0.1.0 sorts before 1.0.10.
        assert!(
            out.find("version = \"0.1.0\"\ndependencies = [\n \"reachc-runtime\"")
                .unwrap()
                < out.find("version = \"1.0.10\"").unwrap()
        );
        assert_eq!(version_cmp("0.9.0", "0.10.0"), Ordering::Less);
        assert_eq!(version_cmp("1.0.0-rc1", "1.0.0"), Ordering::Less);
        assert!(crate_lock("not a lock", "x").is_none());
    }
}

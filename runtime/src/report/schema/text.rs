//! The text of a document as reachc writes it: pretty-printed, with every array of scalars on
//! one line, non-finite numbers as `null`.

use super::{ResultJson, SimJson};
use serde::Serialize;

impl ResultJson {
    /// The result file's text.
    pub fn to_text(&self) -> String {
        text(self)
    }
}

impl SimJson {
    /// The Monte Carlo report's text.
    pub fn to_text(&self) -> String {
        text(self)
    }
}

/// `doc` pretty-printed, arrays of scalars inline.
fn text(doc: &impl Serialize) -> String {
    // Plain data with string keys: serialising cannot fail.
    inline_scalar_arrays(&serde_json::to_string_pretty(doc).expect("a document serialises"))
}

/// serde_json's pretty output with every array of scalars (numbers, strings, `null`, booleans)
/// on one line: `[\n  1.0,\n  2.0\n]` becomes `[1.0, 2.0]` (half the size of a result file, and
/// one line per vector). serde_json writes each array item on its own line and never a newline
/// inside a string, so a line is an item.
fn inline_scalar_arrays(pretty: &str) -> String {
    let lines: Vec<&str> = pretty.lines().collect();
    let mut out = String::with_capacity(pretty.len());
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.ends_with('[') {
            // The items up to the closing bracket at this line's indentation, if all scalars:
            // the search stops at the first item that is not one (an array of objects or
            // arrays is left as it is without reading it to its end, so a file is read once).
            let indent = line.len() - line.trim_start().len();
            let end = lines[i + 1..]
                .iter()
                .map(|l| {
                    let t = l.trim_start();
                    let close = l.len() - t.len() == indent && (t == "]" || t == "],");
                    (close, close || scalar(t.trim_end().trim_end_matches(',')))
                })
                .take_while(|&(_, scalar)| scalar)
                .position(|(close, _)| close);
            if let Some(end) = end {
                out.push_str(line);
                for (j, item) in lines[i + 1..i + 1 + end].iter().enumerate() {
                    if j > 0 {
                        out.push(' ');
                    }
                    out.push_str(item.trim());
                }
                out.push_str(lines[i + 1 + end].trim_start());
                out.push('\n');
                i += end + 2;
                continue;
            }
        }
        out.push_str(line);
        out.push('\n');
        i += 1;
    }
    out.pop();
    out
}

/// Whether one item of serde_json's output is a scalar (a string, number, `null`, `true` or
/// `false`), not the start of an object or array.
fn scalar(item: &str) -> bool {
    let string = item.len() >= 2 && item.starts_with('"') && item.ends_with('"');
    string || !(item.starts_with('{') || item.starts_with('[') || item.is_empty())
}

#[cfg(test)]
mod tests {
    use super::inline_scalar_arrays;

    /// Arrays of scalars go on one line, other arrays keep one item per line, and the text
    /// parses back to the same value (strings holding brackets, commas and escapes included).
    #[test]
    fn scalar_arrays_inline() {
        let v = serde_json::json!({
            "states": ["x[1]", "y, [z]", "q\"[", ""],
            "lo": [1.0, -2.5e-300, null],
            "empty": [],
            "nested": [[1, 2], [3]],
            "objects": [{"a": [true, false]}, {"b": {}}],
            "mixed": [1, [2], {"c": 3}],
        });
        let pretty = serde_json::to_string_pretty(&v).unwrap();
        let inline = inline_scalar_arrays(&pretty);
        let back: serde_json::Value = serde_json::from_str(&inline).unwrap();
        assert_eq!(back, v);
        assert!(
            inline.contains(r#""states": ["x[1]", "y, [z]", "q\"[", ""]"#),
            "{inline}"
        );
        assert!(
            inline.contains(r#""lo": [1.0, -2.5e-300, null],"#),
            "{inline}"
        );
        assert!(inline.contains("\"empty\": [],"), "{inline}");
        assert!(inline.contains("    [1, 2],\n    [3]\n"), "{inline}");
        assert!(inline.contains("\"a\": [true, false]"), "{inline}");
        assert!(
            inline.contains("\"mixed\": [\n    1,\n    [2],\n"),
            "{inline}"
        );
        assert!(inline.len() < pretty.len());
    }
}

//! Loading tabulated signals from CSV files.

use std::path::Path;

use crate::driver::{read_capped, ReadError};
use crate::ir::Table;
use crate::limits::MAX_TABLE_LEN;

/// Reads a CSV table: a header line of column names (the first is time), then rows of finite
/// numbers with strictly increasing times. Also accepted, as documented: blank lines and lines
/// starting with `#` (comments, anywhere), CRLF line ends, spaces around cells. At most
/// [`MAX_TABLE_LEN`] bytes are read. Errors are `"SHOWN:LINE: what"` strings, where `shown` is
/// the path as the spec wrote it.
pub(super) fn load(name: &str, path: &Path, shown: &str) -> Result<Table, String> {
    let bytes = read_capped(path, MAX_TABLE_LEN).map_err(|e| match e {
        ReadError::Io(e) => format!("{shown}: cannot read: {e}"),
        ReadError::NotRegular(kind) => {
            format!("{shown}: not a regular file ({kind}); a table is read from a CSV file")
        }
        ReadError::TooLarge => {
            format!("{shown}: the file is larger than the limit of {MAX_TABLE_LEN} bytes (8 MiB)")
        }
    })?;
    let text = String::from_utf8(bytes).map_err(|e| {
        format!(
            "{shown}: not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        )
    })?;
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (header_line, header) = lines.next().ok_or_else(|| {
        format!("{shown}:1: the file is empty; expected a header line like `t,px,py`")
    })?;
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    if names.len() < 2 {
        return Err(format!(
            "{shown}:{header_line}: the header needs a time column and at least one data column"
        ));
    }
    for (i, n) in names.iter().enumerate() {
        let ok = n
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !ok {
            return Err(format!(
                "{shown}:{header_line}: column {} has name `{n}`, which is not an identifier",
                i + 1
            ));
        }
        if names[..i].contains(n) {
            return Err(format!("{shown}:{header_line}: column `{n}` appears twice"));
        }
    }
    let mut times = Vec::new();
    let mut values = vec![Vec::new(); names.len() - 1];
    for (line, row) in lines {
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(format!(
                "{shown}:{line}: expected {} values, found {}",
                names.len(),
                cells.len()
            ));
        }
        for (col, cell) in cells.iter().enumerate() {
            let v: f64 = cell
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{shown}:{line}: `{cell}` in column `{}` is not a finite number",
                        names[col]
                    )
                })?;
            if col == 0 {
                if times.last().is_some_and(|&last| v <= last) {
                    return Err(format!(
                        "{shown}:{line}: time {v} is not greater than the previous time; times must increase strictly"
                    ));
                }
                times.push(v);
            } else {
                values[col - 1].push(v);
            }
        }
    }
    if times.len() < 2 {
        return Err(format!(
            "{shown}: a table needs at least two rows of data, found {}",
            times.len()
        ));
    }
    Ok(Table {
        name: name.to_string(),
        columns: names[1..].to_vec(),
        times,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load_text(text: &str) -> Result<Table, String> {
        let dir = std::env::temp_dir().join(format!("reachc-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!(
            "{:x}.csv",
            text.len() * 31 + text.bytes().map(usize::from).sum::<usize>()
        ));
        std::fs::write(&path, text).unwrap();
        let r = load("ref", &path, "");
        std::fs::remove_file(&path).unwrap();
        r
    }

    #[test]
    fn good_table() {
        let t = load_text("t, px, py\n0, 1, 2\n# comment\n0.5, 3, 4\n").unwrap();
        assert_eq!(t.columns, vec!["px", "py"]);
        assert_eq!(t.times, vec![0.0, 0.5]);
        assert_eq!(t.values, vec![vec![1.0, 3.0], vec![2.0, 4.0]]);
    }

    #[test]
    fn bad_tables() {
        assert_eq!(
            load_text("t,x\n0,1\n1\n").unwrap_err(),
            ":3: expected 2 values, found 1"
        );
        assert_eq!(
            load_text("t,x\n0,1\n0,2\n").unwrap_err(),
            ":3: time 0 is not greater than the previous time; times must increase strictly"
        );
        assert_eq!(
            load_text("t,x\n0,abc\n1,2\n").unwrap_err(),
            ":2: `abc` in column `x` is not a finite number"
        );
        assert_eq!(
            load_text("t,x\n0,inf\n1,2\n").unwrap_err(),
            ":2: `inf` in column `x` is not a finite number"
        );
        assert_eq!(
            load_text("t,x\n0,1\n").unwrap_err(),
            ": a table needs at least two rows of data, found 1"
        );
        assert_eq!(
            load_text("t,x y\n").unwrap_err(),
            ":1: column 2 has name `x y`, which is not an identifier"
        );
    }
}

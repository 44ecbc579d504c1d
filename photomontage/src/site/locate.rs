//! Finding the line of a field in site TOML text, for error messages.

/// 1-based line and column of a byte offset.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(offset, |nl| offset - nl - 1) + 1;
    (line, column)
}

/// The 1-based line of a field path like `observations[3].photo` or `lighting.sky_model`:
/// the `key =` line inside the (n+1)-th `[[observations]]` table, or the table header if the key
/// is not written there, or 0 when nothing matches.
pub(super) fn field_line(text: &str, field: &str) -> usize {
    let mut parts = field.split('.');
    let Some(first) = parts.next() else {
        return 0;
    };
    let rest: Vec<&str> = parts.collect();
    let (table, index) = match first.split_once('[') {
        Some((name, idx)) => (name, idx.trim_end_matches(']').parse::<usize>().ok()),
        None => (first, None),
    };
    let lines: Vec<&str> = text.lines().collect();
    let header_start = match index {
        Some(n) => {
            let header = format!("[[{table}]]");
            lines
                .iter()
                .enumerate()
                .filter(|(_, l)| l.trim() == header)
                .nth(n)
                .map(|(i, _)| i)
        }
        None if rest.is_empty() => {
            // a top-level key
            return find_key(&lines, 0, first).map_or(0, |i| i + 1);
        }
        None => {
            let header = format!("[{table}]");
            lines.iter().position(|l| l.trim() == header)
        }
    };
    let Some(start) = header_start else {
        return 0;
    };
    let key = rest.first().copied().unwrap_or("");
    find_key(&lines, start + 1, key).map_or(start + 1, |i| i + 1)
}

/// The index of the line assigning `key` from `start` until the next table header.
fn find_key(lines: &[&str], start: usize, key: &str) -> Option<usize> {
    for (i, line) in lines.iter().enumerate().skip(start) {
        let t = line.trim_start();
        if t.starts_with('[') {
            return None;
        }
        if let Some(after) = t.strip_prefix(key)
            && after.trim_start().starts_with('=')
        {
            return Some(i);
        }
    }
    None
}

//! The text of a scene file, for turning byte offsets into lines and entries.

/// A scene file's name and text.
pub struct Source<'a> {
    /// The file, as the user named it.
    pub file: &'a str,
    /// Its contents.
    pub text: &'a str,
}

impl Source<'_> {
    /// 1-based line of byte `offset`.
    pub fn line_of(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    /// 1-based line where `field` of the entry starting at byte `offset`
    /// is written: the first line from there, before the next table
    /// header, that assigns its first component (`gate` of `gate.above`)
    /// as `key =`, inline tables included; the entry's own line when the
    /// field is not written (a default) or not found.
    pub fn field_line(&self, offset: usize, field: &str) -> usize {
        let first = self.line_of(offset);
        let key = field.split(['.', '[']).next().unwrap_or("");
        if key.is_empty() {
            return first;
        }
        for (i, line) in self.text.lines().enumerate().skip(first - 1) {
            if i + 1 > first && header(line).is_some() {
                break;
            }
            if assigns(line, key) {
                return i + 1;
            }
        }
        first
    }

    /// Byte offset of the line holding the header `[name]` (a table, not
    /// an array of tables), if the file has one.
    pub fn table_offset(&self, name: &str) -> Option<usize> {
        let mut offset = 0;
        for line in self.text.split_inclusive('\n') {
            if header(line).is_some_and(|(h, array)| !array && h == name) {
                return Some(offset);
            }
            offset += line.len();
        }
        None
    }

    /// The table entry that encloses byte `offset`: `name[k]` for the k-th
    /// (0-based) `[[name]]` header before it, `name` for a `[name]` table, or
    /// `None` at top level.
    pub fn entry_at(&self, offset: usize) -> Option<String> {
        // Whole lines up to and including the one holding `offset`: a header
        // cut in the middle would give a garbled name.
        let end = self.text[offset.min(self.text.len())..]
            .find('\n')
            .map_or(self.text.len(), |i| offset.min(self.text.len()) + i);
        let mut counts: Vec<(String, usize)> = Vec::new();
        let mut current = None;
        for line in self.text[..end].lines() {
            match header(line) {
                Some((name, true)) => {
                    let k = match counts.iter_mut().find(|(n, _)| *n == name) {
                        Some((_, c)) => {
                            *c += 1;
                            *c - 1
                        }
                        None => {
                            counts.push((name.clone(), 1));
                            0
                        }
                    };
                    current = Some(format!("{name}[{k}]"));
                }
                Some((name, false)) => current = Some(name),
                None => {}
            }
        }
        current
    }

    /// The key assigned on the line containing `offset`, if that line is
    /// `key = value`.
    pub fn key_at(&self, offset: usize) -> Option<String> {
        let start = self.text[..offset.min(self.text.len())]
            .rfind('\n')
            .map_or(0, |i| i + 1);
        let line = self.text[start..].lines().next()?;
        let (key, _) = line.split_once('=')?;
        let key = key.trim();
        let ok = !key.is_empty()
            && key
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        ok.then(|| key.to_string())
    }
}

/// Whether `line` assigns `key` (`key = ...`, `{ key = ...`, `, key = ...`),
/// outside a comment.
fn assigns(line: &str, key: &str) -> bool {
    let code = line.split('#').next().unwrap_or("");
    let bytes = code.as_bytes();
    let mut from = 0;
    while let Some(i) = code[from..].find(key).map(|i| i + from) {
        let before = code[..i].trim_end();
        let starts = before.is_empty() || before.ends_with('{') || before.ends_with(',');
        let after = code[i + key.len()..].trim_start();
        let word_ends = bytes
            .get(i + key.len())
            .is_none_or(|b| !(b.is_ascii_alphanumeric() || *b == b'_' || *b == b'-'));
        if starts && word_ends && after.starts_with('=') && !after.starts_with("==") {
            return true;
        }
        from = i + key.len();
    }
    false
}

/// The table a header line opens: `([[name]]` → `(name, true)`, `[name]` →
/// `(name, false)`), tolerating spaces and a missing closing bracket; `None`
/// for any other line or an empty name.
fn header(line: &str) -> Option<(String, bool)> {
    let line = line.trim();
    let (rest, array) = match line.strip_prefix("[[") {
        Some(rest) => (rest, true),
        None => (line.strip_prefix('[')?, false),
    };
    let name: String = rest
        .split(']')
        .next()
        .unwrap_or("")
        .split('.')
        .map(str::trim)
        .collect::<Vec<_>>()
        .join(".");
    let ok = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
        && !name.split('.').any(str::is_empty);
    ok.then_some((name, array))
}

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

    /// The table entry that encloses byte `offset`: `name[k]` for the k-th
    /// (0-based) `[[name]]` header before it, `name` for a `[name]` table, or
    /// `None` at top level.
    pub fn entry_at(&self, offset: usize) -> Option<String> {
        let before = &self.text[..offset.min(self.text.len())];
        let mut counts: Vec<(String, usize)> = Vec::new();
        let mut current = None;
        for line in before.lines() {
            let line = line.trim();
            if let Some(name) = line.strip_prefix("[[").and_then(|l| l.split("]]").next()) {
                let name = name.trim().to_string();
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
            } else if let Some(name) = line.strip_prefix('[').and_then(|l| l.split(']').next()) {
                current = Some(name.trim().to_string());
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

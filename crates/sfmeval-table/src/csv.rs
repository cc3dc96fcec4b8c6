//! CSV as the runner writes it (`table1.csv`, `runs.csv`, `sweep.csv`): comma-separated, one
//! record a line ending in `\n`, a field in double quotes (its quotes doubled) when it holds a
//! comma, a quote or a line break.

/// One field as CSV text: quoted when it holds `,`, `"` or `\n`, as is otherwise.
pub fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A CSV document written record by record.
#[derive(Debug, Default)]
pub struct CsvWriter {
    text: String,
}

impl CsvWriter {
    /// An empty document.
    pub fn new() -> CsvWriter {
        CsvWriter::default()
    }

    /// Appends one record: the fields quoted as [`field`] does, separated by commas, then a
    /// line break.
    pub fn record<S: AsRef<str>>(&mut self, fields: impl IntoIterator<Item = S>) {
        for (i, f) in fields.into_iter().enumerate() {
            if i > 0 {
                self.text.push(',');
            }
            self.text.push_str(&field(f.as_ref()));
        }
        self.text.push('\n');
    }

    /// The document's text.
    pub fn finish(self) -> String {
        self.text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_only_where_needed() {
        assert_eq!(field("plain"), "plain");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(field("two\nlines"), "\"two\nlines\"");
        let mut w = CsvWriter::new();
        w.record(["a", "b,c", ""]);
        w.record(Vec::<String>::new());
        assert_eq!(w.finish(), "a,\"b,c\",\n\n");
    }
}

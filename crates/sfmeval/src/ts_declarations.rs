//! The npm package's TypeScript declarations of report types (`crates/sfmeval-wasm/js/*.d.ts`),
//! generated from the Rust types by ts-rs (feature `ts`), for the tests of this crate and of the
//! benchmark crates that write and check them (`scripts/gen-report-types.sh`). Feature `ts` is
//! test support only: no build a user runs turns it on, so the file access of
//! [`check_committed`] does not reach the core's front ends.

use std::collections::BTreeMap;

use ts_rs::{Config, TS, TypeVisitor};

/// Every declarable type reachable from the types added, each once, by name, so that a file's
/// text depends on the types alone (ts-rs visits dependencies in an order that changes with the
/// build, e.g. the checkout's path).
pub struct Declarations {
    cfg: Config,
    /// The declaration (`type X = ...`) and its text (doc comment, `export type ...`) by name.
    by_name: BTreeMap<String, (String, String)>,
}

impl Default for Declarations {
    fn default() -> Self {
        Self::new()
    }
}

impl Declarations {
    /// None yet; 64-bit integers are declared `number` (`JSON.parse` reads JSON numbers so, not
    /// as `bigint`).
    pub fn new() -> Self {
        Self {
            cfg: Config::new().with_large_int("number"),
            by_name: BTreeMap::new(),
        }
    }

    /// Adds `T` and every type it refers to.
    pub fn add<T: TS + 'static + ?Sized>(mut self) -> Self {
        self.visit::<T>();
        self
    }

    /// Whether a type of this name is declared.
    pub fn declares(&self, name: &str) -> bool {
        self.by_name.contains_key(name)
    }

    /// The text of a `.d.ts` file: the two header lines naming `schema` and the crate the types
    /// come from, an import from `./report.js` of the types `shared` (the core report's) declares
    /// too, then the declaration of `first` and the others by name, each line without trailing
    /// spaces (ts-rs leaves one after each field).
    pub fn file_text(
        mut self,
        schema: &str,
        crate_dir: &str,
        first: &str,
        shared: Option<&Declarations>,
    ) -> String {
        let mut out = format!(
            "// The `{schema}` report's types, generated from the Rust types of\n\
             // {crate_dir} (feature `ts`, ts-rs) by scripts/gen-report-types.sh: do not edit.\n"
        );
        let imported: Vec<String> = shared.map_or_else(Vec::new, |s| {
            self.by_name
                .keys()
                .filter(|n| s.declares(n))
                .cloned()
                .collect()
        });
        if !imported.is_empty() {
            out.push_str(&format!(
                "import type {{ {} }} from './report.js';\n",
                imported.join(", ")
            ));
        }
        for name in &imported {
            self.by_name.remove(name);
        }
        let head = self.by_name.remove(first);
        for (_, text) in head.into_iter().chain(self.by_name.into_values()) {
            out.push_str(&text);
        }
        out.lines().map(|l| format!("{}\n", l.trim_end())).collect()
    }
}

impl TypeVisitor for Declarations {
    fn visit<T: TS + 'static + ?Sized>(&mut self) {
        // primitives and containers have no declaration of their own
        if T::output_path().is_none() {
            return;
        }
        // one declaration a name (serde_json's `Value` and `Map` both declare `JsonValue`)
        let decl = T::decl(&self.cfg);
        let name = T::ident(&self.cfg);
        if let Some((earlier, _)) = self.by_name.get(&name) {
            assert_eq!(*earlier, decl, "two report types named {name}");
            return;
        }
        let mut text = String::from("\n");
        if let Some(docs) = T::docs() {
            text.push_str(&docs);
        }
        text.push_str("export ");
        text.push_str(&decl);
        text.push('\n');
        self.by_name.insert(name, (decl, text));
        T::visit_dependencies(self);
    }
}

/// Checks that the committed file `file` (relative to `manifest_dir`, the calling crate's
/// folder) is `text`, writing it first when `SFMEVAL_WRITE_REPORT_TYPES` is set; `schema` must
/// appear in it as the `schema` field's type.
///
/// # Panics
/// When the file differs (the test's failure: run `scripts/gen-report-types.sh`).
pub fn check_committed(manifest_dir: &str, file: &str, schema: &str, text: &str) {
    assert!(text.contains(&format!("schema: \"{schema}\"")), "{text}");
    let path = std::path::Path::new(manifest_dir).join(file);
    if std::env::var_os("SFMEVAL_WRITE_REPORT_TYPES").is_some()
        && let Err(e) = std::fs::write(&path, text)
    {
        panic!("cannot write {}: {e}", path.display());
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == text,
        "{} is not what the {schema} report types generate: run scripts/gen-report-types.sh",
        path.display()
    );
}

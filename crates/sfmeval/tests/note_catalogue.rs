//! The note codes are a contract: the core's catalogue (`sfmeval::note::Code::ALL`), the
//! report schema's enum and the table in `docs/notes.md` list the same codes with the same
//! levels and meanings.

use std::path::Path;

use sfmeval::note::Code;

fn repo_file(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_schema_lists_every_code_in_catalogue_order() {
    let schema: serde_json::Value =
        serde_json::from_str(&repo_file("schemas/report.schema.json")).unwrap();
    let listed: Vec<&str> = schema["$defs"]["note"]["properties"]["code"]["enum"]
        .as_array()
        .expect("the note code enum")
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let ours: Vec<&str> = Code::ALL.iter().map(|c| c.as_str()).collect();
    assert_eq!(listed, ours);
}

#[test]
fn the_docs_table_lists_every_code_with_its_level_and_meaning() {
    let docs = repo_file("docs/notes.md");
    let rows: Vec<(String, String, String)> = docs
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.trim().trim_matches('|').split(" | ").collect();
            let code = cells.first()?.trim().strip_prefix('`')?.strip_suffix('`')?;
            Some((
                code.to_string(),
                cells.get(1)?.trim().to_string(),
                cells.get(2)?.trim().to_string(),
            ))
        })
        .collect();
    let ours: Vec<(String, String, String)> = Code::ALL
        .iter()
        .map(|c| {
            (
                c.as_str().to_string(),
                c.level().as_str().to_string(),
                c.meaning().split_whitespace().collect::<Vec<_>>().join(" "),
            )
        })
        .collect();
    assert_eq!(rows, ours);
}

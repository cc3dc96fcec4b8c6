//! HTML text: escaping, and the page shell of the runner's self-contained pages (the tables'
//! `index.html`, `sweep.html`): inline style, no scripts, nothing loaded.

/// HTML-escapes text (for element content and attribute values).
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The style every page starts with (body and tables).
const BASE_STYLE: &str = "body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}table{border-collapse:collapse;margin:1em 0;font-size:13px}\n";

/// A whole page: the document head with `title` and the base style followed by `style`, then
/// `body` (HTML, ending with a line break).
pub fn page(title: &str, style: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n<style>\n{BASE_STYLE}{style}\n</style></head><body>\n{body}</body></html>\n",
        esc(title)
    )
}

//! Text for table cells and tooltips.

/// `s` on one line (line breaks become spaces), cut after `max_chars` characters with `…`.
pub fn one_line(s: &str, max_chars: usize) -> String {
    let one = s.replace('\n', " ");
    if one.chars().count() > max_chars {
        format!("{}…", one.chars().take(max_chars).collect::<String>())
    } else {
        one
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_cuts_by_characters() {
        assert_eq!(one_line("a\nb", 5), "a b");
        assert_eq!(one_line("ééééé", 3), "ééé…");
        assert_eq!(one_line("abc", 3), "abc");
    }
}

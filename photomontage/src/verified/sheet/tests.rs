use super::*;

#[test]
fn winansi_maps_latin1_and_names_the_rest() {
    assert_eq!(winansi("abc 1.5"), b"abc 1.5".to_vec());
    assert_eq!(winansi("30°"), vec![b'3', b'0', 0xB0]);
    assert_eq!(winansi("4×3"), vec![b'4', 0xD7, b'3']);
    assert_eq!(winansi("σ"), b"sigma".to_vec());
    assert_eq!(winansi("Δ"), b"?".to_vec());
}

#[test]
fn characters_per_width() {
    // 10 pt DejaVu Sans Mono: 6.02 pt = 2.124 mm per character.
    assert_eq!(chars_in(100.0, 10.0), 47);
    assert_eq!(chars_in(0.0, 10.0), 0);
}

#[test]
fn wrapping_at_spaces() {
    assert_eq!(wrap("aa bb cc dd", 5), vec!["aa bb", "cc dd"]);
    assert_eq!(wrap("short", 10), vec!["short"]);
    assert_eq!(wrap("", 10), vec![""]);
}

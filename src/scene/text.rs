//! Text from a scene file as it may appear in a message: escaped and cut
//! short. A file's bytes reach a terminal only through [`quote`] (names,
//! keys, words of a line) or, as a backstop for every message a loader
//! returns, [`sanitize`]: an escape sequence in a vertex line must not clear
//! the screen, a NUL must not be printed, and a 10 MB name must not make a
//! 10 MB message.

/// Characters of file text a message shows at most, per quoted item.
pub const QUOTE_CHARS: usize = 40;

/// Characters of a whole message ([`sanitize`]): room for a few paths and
/// quoted items, not for a file.
pub const MESSAGE_CHARS: usize = 2000;

/// Whether `c` is shown escaped: control characters (C0, DEL, C1), and the
/// format characters that reorder or hide text (bidirectional overrides,
/// zero-width characters, the byte-order mark).
fn hidden(c: char) -> bool {
    c.is_control()
        || matches!(c,
            '\u{200B}'..='\u{200F}'
            | '\u{202A}'..='\u{202E}'
            | '\u{2060}'..='\u{2069}'
            | '\u{FEFF}'
            | '\u{FFF9}'..='\u{FFFB}')
}

/// Appends `c` to `out`, escaped as Rust writes it (`\u{1b}`) when hidden.
fn push(out: &mut String, c: char) {
    if hidden(c) {
        match c {
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            '\n' => out.push_str("\\n"),
            _ => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
        }
    } else {
        out.push(c);
    }
}

/// `s` as a message quotes it: hidden characters escaped, cut to
/// [`QUOTE_CHARS`] characters with the length of the whole said.
pub fn quote(s: &str) -> String {
    quote_at_most(s, QUOTE_CHARS)
}

/// [`quote`] with a limit of `max` characters.
pub fn quote_at_most(s: &str, max: usize) -> String {
    let mut out = String::new();
    let mut chars = s.chars();
    for c in chars.by_ref().take(max) {
        push(&mut out, c);
    }
    if chars.next().is_some() {
        out.push_str(&format!("... ({} bytes in all)", s.len()));
    }
    out
}

/// Bytes of a file as a message quotes them: invalid UTF-8 shown as
/// `\x..`, then as [`quote`].
pub fn quote_bytes(b: &[u8]) -> String {
    let head = &b[..b.len().min(4 * QUOTE_CHARS)];
    let mut s = String::new();
    for chunk in head.utf8_chunks() {
        s.push_str(chunk.valid());
        for x in chunk.invalid() {
            s.push_str(&format!("\\x{x:02x}"));
        }
    }
    let mut q = quote(&s);
    if b.len() > head.len() && !q.ends_with("in all)") {
        q.push_str(&format!("... ({} bytes in all)", b.len()));
    }
    q
}

/// A whole message made safe to print: hidden characters escaped (a
/// newline too, so one message is one line) and, past [`MESSAGE_CHARS`],
/// its middle cut out, keeping its start (where) and end (why).
pub fn sanitize(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(4 * MESSAGE_CHARS));
    let total = message.chars().count();
    if total <= MESSAGE_CHARS {
        for c in message.chars() {
            push(&mut out, c);
        }
        return out;
    }
    let keep_head = MESSAGE_CHARS * 2 / 3;
    let keep_tail = MESSAGE_CHARS - keep_head;
    for c in message.chars().take(keep_head) {
        push(&mut out, c);
    }
    out.push_str(&format!(
        " [... {} characters cut ...] ",
        total - keep_head - keep_tail
    ));
    for c in message.chars().skip(total - keep_tail) {
        push(&mut out, c);
    }
    out
}

/// Characters of a path a message shows: a path from a file's name is
/// bounded by the system's `PATH_MAX` (4096) only once it is opened.
pub const PATH_CHARS: usize = 300;

/// `p` as a message shows it: [`quote_at_most`] with [`PATH_CHARS`].
pub fn path<P: AsRef<std::path::Path> + ?Sized>(p: &P) -> String {
    quote_at_most(&p.as_ref().display().to_string(), PATH_CHARS)
}

/// `x` for a message: in scientific notation where plain notation would
/// be long (1e-40 is forty digits as `{}` writes it).
pub fn number<T>(x: T) -> String
where
    T: Into<f64> + Copy + std::fmt::Display + std::fmt::LowerExp,
{
    let v: f64 = x.into();
    if v != 0.0 && v.is_finite() && !(1e-3..1e9).contains(&v.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `s` without a UTF-8 byte-order mark at its start: editors on Windows
/// write one, and it is no part of the first keyword.
pub fn strip_bom(s: &[u8]) -> &[u8] {
    s.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_cuts() {
        assert_eq!(quote("v\u{1b}[2J"), "v\\u{1b}[2J");
        assert_eq!(quote("a\0b"), "a\\u{0}b");
        assert_eq!(quote("\u{202e}txt"), "\\u{202e}txt");
        let long = "x".repeat(10_000_000);
        let q = quote(&long);
        assert!(q.len() < 100 && q.contains("10000000 bytes"), "{q}");
        assert_eq!(quote_bytes(b"a\xffb"), "a\\xffb");
        let m = sanitize(&format!("start {} end", "y".repeat(100_000)));
        assert!(m.len() < MESSAGE_CHARS + 100 && m.starts_with("start") && m.ends_with("end"));
        assert_eq!(sanitize("a\nb"), "a\\nb");
        assert_eq!(strip_bom(b"\xEF\xBB\xBFmtllib"), b"mtllib");
    }
}

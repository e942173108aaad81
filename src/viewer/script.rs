//! `isr view --script FILE`: timed input for tests and demos. One command a
//! line, times in seconds from the first presented frame:
//!
//! ```text
//! 0.5 key M            # press a key (names: `controls::Key::from_name`)
//! 1.0 screenshot a.png # the presented image, overlay included, as PNG
//! 1.5 resize 640 360   # ask the window system for a new window size
//! 2.0 quit
//! ```
//!
//! Blank lines and text after `#` are ignored. Commands run in time order
//! (lines with equal times in file order), each on the first frame at or
//! after its time; a screenshot shows the commands before it applied, none
//! after it.

use super::controls::Key;
use anyhow::{bail, Context as _, Result};
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    Key(Key),
    Screenshot(PathBuf),
    Resize(u32, u32),
    Quit,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Timed {
    pub seconds: f64,
    pub command: Command,
}

/// Largest window side a script may ask for.
const MAX_SIDE: u32 = 16384;

/// Parses a script's text; errors name the line.
pub fn parse(text: &str) -> Result<Vec<Timed>> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let timed =
            parse_line(line).with_context(|| format!("line {}: `{}`", i + 1, raw.trim()))?;
        out.push(timed);
    }
    // Stable: equal times keep the file's order.
    out.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
    Ok(out)
}

fn parse_line(line: &str) -> Result<Timed> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let seconds: f64 = words[0]
        .parse()
        .ok()
        .filter(|s: &f64| s.is_finite() && *s >= 0.0)
        .with_context(|| {
            format!(
                "`{}` is not a time: each line starts with seconds (a number >= 0)",
                words[0]
            )
        })?;
    let Some(&verb) = words.get(1) else {
        bail!("a time needs a command after it: key NAME, screenshot PATH, resize W H or quit");
    };
    let args = &words[2..];
    let want = |n: usize, usage: &str| -> Result<()> {
        if args.len() != n {
            bail!("`{verb}` takes {n} argument(s): {usage}");
        }
        Ok(())
    };
    let command = match verb {
        "key" => {
            want(1, "key NAME")?;
            Command::Key(Key::from_name(args[0])?)
        }
        "screenshot" => {
            want(1, "screenshot PATH.png")?;
            let path = PathBuf::from(args[0]);
            if path.extension().and_then(|e| e.to_str()) != Some("png") {
                bail!("screenshot {}: the path must end in .png", args[0]);
            }
            Command::Screenshot(path)
        }
        "resize" => {
            want(2, "resize WIDTH HEIGHT")?;
            let side = |s: &str| -> Result<u32> {
                s.parse::<u32>()
                    .ok()
                    .filter(|v| (1..=MAX_SIDE).contains(v))
                    .with_context(|| {
                        format!("resize: `{s}` is not a size in pixels (1 to {MAX_SIDE})")
                    })
            };
            Command::Resize(side(args[0])?, side(args[1])?)
        }
        "quit" => {
            want(0, "quit")?;
            Command::Quit
        }
        other => bail!(
            "unknown command `{other}`: expected key NAME, screenshot PATH, resize W H or quit"
        ),
    };
    Ok(Timed { seconds, command })
}

/// Reads and parses a script file.
pub fn load(path: &Path) -> Result<Vec<Timed>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the script {}", path.display()))?;
    parse(&text).with_context(|| format!("script {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_orders_commands() {
        let s = parse(
            "# demo\n2 quit\n0.5 key m\n\n1 screenshot out/a.png  # shot\n1 resize 640 360\n",
        )
        .unwrap();
        assert_eq!(
            s,
            vec![
                Timed {
                    seconds: 0.5,
                    command: Command::Key(Key::Method)
                },
                Timed {
                    seconds: 1.0,
                    command: Command::Screenshot("out/a.png".into())
                },
                Timed {
                    seconds: 1.0,
                    command: Command::Resize(640, 360)
                },
                Timed {
                    seconds: 2.0,
                    command: Command::Quit
                },
            ]
        );
    }

    #[test]
    fn errors_name_the_line() {
        for (text, needle) in [
            ("1 quit\nsoon key M", "line 2"),
            ("1 key Hyper", "unknown key"),
            ("1 screenshot a.jpg", ".png"),
            ("1 resize 0 10", "not a size"),
            ("-1 quit", "not a time"),
            ("1", "needs a command"),
            ("1 jump", "unknown command"),
            ("1 quit now", "takes 0"),
        ] {
            let e = format!("{:#}", parse(text).unwrap_err());
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }
}

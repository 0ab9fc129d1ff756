//! Parsers for the flags the settings types share ([`crate::sim::settings`],
//! [`crate::sim::import`], and the decode layer's): numbers in a range, pairs, and a
//! parser error as the one line a user reads.

/// A settings group `T` (a `clap` argument group) parsed from a command's flags given as
/// strings, with no binary name first: how the settings types serve both the `slf` command
/// and the Python package with one parser. `command` names the group in clap's messages.
///
/// # Errors
/// The parser's message, one line ([`one_line`]), naming the flag.
pub fn parse<T, I, S>(command: &'static str, flags: I) -> Result<T, String>
where
    T: clap::Args + clap::FromArgMatches,
    I: IntoIterator<Item = S>,
    S: Into<std::ffi::OsString> + Clone,
{
    let cmd = T::augment_args(clap::Command::new(command).no_binary_name(true));
    cmd.try_get_matches_from(flags).and_then(|m| T::from_arg_matches(&m)).map_err(|e| one_line(&e))
}

/// A parser error as one line: its first, without clap's `error: ` prefix.
fn one_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let line = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("invalid flags");
    line.trim_start_matches("error: ").to_string()
}

/// A finite number above zero, for clap.
///
/// # Errors
/// Anything else, quoted.
pub fn positive(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a finite number above 0")),
    }
}

/// A pair `A,B` of whole numbers, for clap.
///
/// # Errors
/// Anything else, quoted.
pub fn pair(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s.split_once(',').ok_or_else(|| format!("{s:?} is not a pair A,B"))?;
    let num = |t: &str| t.trim().parse::<usize>().map_err(|_| format!("{t:?} in {s:?} is not a whole number"));
    Ok((num(a)?, num(b)?))
}

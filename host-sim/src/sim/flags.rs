//! Parsers for the flags the settings types share ([`crate::sim::settings`],
//! [`crate::sim::import`], and the decode layer's): numbers in a range, pairs, and a
//! parser error as the one line a user reads.

/// A parser error as one line: its first, without clap's `error: ` prefix.
pub fn one_line(e: &clap::Error) -> String {
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

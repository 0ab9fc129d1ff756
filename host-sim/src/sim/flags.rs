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
    let cmd = negative_numbers(T::augment_args(clap::Command::new(command).no_binary_name(true)));
    cmd.try_get_matches_from(flags).and_then(|m| T::from_arg_matches(&m)).map_err(|e| one_line(&e))
}

/// A settings group that `slf` parses from a command's flags and the Python package from
/// the same flags given as strings: its parser is [`parse`] under [`Self::COMMAND`].
pub trait FromFlags: clap::Args + clap::FromArgMatches + Sized {
    /// The command the group belongs to, as clap's messages name it.
    const COMMAND: &'static str;

    /// The settings from the command's flags, without the binary name and the command's
    /// own positional arguments and `-o` (e.g. `["--mask=lenslet", "--snapshots=3"]` for
    /// `slf simulate`).
    ///
    /// # Errors
    /// The parser's message, one line, naming the flag (e.g. `invalid value '7' for
    /// '--stride <STRIDE>': 7 is not in 1..=5`).
    fn from_flags<I, S>(flags: I) -> Result<Self, String>
    where
        I: IntoIterator<Item = S>,
        S: Into<std::ffi::OsString> + Clone,
    {
        parse(Self::COMMAND, flags)
    }
}

/// `cmd` and every subcommand under it taking values that look like negative numbers
/// (`--defects -0.1`) as values, for their parser to refuse by range, not as unknown flags
/// ("unexpected argument '-0' found").
pub fn negative_numbers(cmd: clap::Command) -> clap::Command {
    cmd.allow_negative_numbers(true).mut_subcommands(negative_numbers)
}

/// A parser error as one line, without clap's `error: ` prefix: its message and the lines
/// that continue it (the arguments a "required arguments were not provided:" names), up to
/// the usage and tips after the first blank line.
pub fn one_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let line = text
        .lines()
        .map(str::trim)
        .skip_while(|l| l.is_empty())
        .take_while(|l| !l.is_empty() && !l.starts_with("Usage:"))
        .collect::<Vec<_>>()
        .join(" ");
    let line = line.trim_start_matches("error: ");
    if line.is_empty() { "invalid flags".to_string() } else { line.to_string() }
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

#[cfg(test)]
mod tests {
    use crate::sim::flags::{one_line, parse, positive};

    #[derive(clap::Parser, Debug)]
    struct Cmd {
        #[arg(long)]
        output: String,
        #[arg(long, value_parser = positive)]
        scale: Option<f32>,
    }

    /// Issue 41, item 14: a missing required argument is named on the one line.
    #[test]
    fn a_missing_argument_is_named() {
        let e = <Cmd as clap::Parser>::try_parse_from(["x"]).unwrap_err();
        assert_eq!(one_line(&e), "the following required arguments were not provided: --output <OUTPUT>");
        let e = <Cmd as clap::Parser>::try_parse_from(["x", "--output", "a", "--nope"]).unwrap_err();
        assert_eq!(one_line(&e), "unexpected argument '--nope' found");
    }

    /// Issue 41, item 15: a negative number is a value, refused by its parser's range, not
    /// "unexpected argument '-0' found".
    #[test]
    fn a_negative_number_is_a_value() {
        #[derive(clap::Args, Debug)]
        struct Group {
            #[arg(long, value_parser = positive)]
            scale: f32,
        }
        let e = parse::<Group, _, _>("x", ["--scale", "-0.1"]).unwrap_err();
        assert!(e.contains("--scale") && e.contains("\"-0.1\" is not a finite number above 0"), "{e}");
        let _ = Cmd { output: String::new(), scale: None };
    }
}

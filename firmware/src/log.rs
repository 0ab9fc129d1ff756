//! The one logging shim: routes to `defmt` with the `defmt` feature, to nothing without.
//!
//! Host builds that call defmt macros need a global logger to link, so the decoder never
//! calls defmt directly. Arguments are still evaluated by
//! reference without the feature, so a variable used only in a log line is not "unused".

/// `log!(level, "format {}", args..)` with `level` one of defmt's macros
/// (`trace`, `debug`, `info`, `warn`, `error`). The format string is defmt's.
#[cfg(feature = "defmt")]
macro_rules! log {
    ($level:ident, $($arg:tt)+) => {
        defmt::$level!($($arg)+)
    };
}

#[cfg(not(feature = "defmt"))]
macro_rules! log {
    ($level:ident, $fmt:literal $(, $arg:expr)* $(,)?) => {{
        $( let _ = &$arg; )*
    }};
}

pub(crate) use log;

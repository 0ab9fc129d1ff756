//! Descriptions read from JSON, with errors that name the field.
//!
//! serde_json alone says "number out of range at line 1 column 285"; a user editing a
//! capture or calibration description wants "white_level: number out of range ...". The
//! path matters more since serde_json's exact float parsing is on (another crate in the
//! build enables `float_roundtrip`): a value past f32's range is then an error, not infinity.

use serde::de::DeserializeOwned;

/// Parses `text` as a `T`; the error starts with the path of the field that failed
/// (`frames[2]`, `white_level`), then serde_json's message with line and column.
///
/// # Errors
/// The field's path and what is wrong with it, in one line.
pub fn parse<T: DeserializeOwned>(text: &str) -> Result<T, String> {
    serde_path_to_error::deserialize(&mut serde_json::Deserializer::from_str(text)).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Deserialize, Debug)]
    #[allow(dead_code)]
    struct Levels {
        black: f32,
        frames: Vec<String>,
    }

    #[test]
    fn the_error_names_the_field_that_failed() {
        let e = parse::<Levels>(r#"{"black": 1e39, "frames": []}"#).unwrap_err();
        assert!(e.starts_with("black: "), "{e}");
        let e = parse::<Levels>(r#"{"black": 1, "frames": ["a", 3]}"#).unwrap_err();
        assert!(e.starts_with("frames[1]: invalid type"), "{e}");
        assert_eq!(parse::<Levels>(r#"{"black": 2.5, "frames": ["a"]}"#).unwrap().black, 2.5);
    }
}

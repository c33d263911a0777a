//! Reading the project's data files (skeletons, motion libraries, worlds): JSON through serde,
//! with errors that name the field where the file goes wrong (`units.wave.keys: …`) and the
//! line and column.

use serde::de::DeserializeOwned;

/// A data file's free-text field for people (`"description"`): accepted, not kept.
pub(crate) type Note = Option<serde::de::IgnoredAny>;

/// `text` read as a `T`; the error names the field path, says what is wrong and where.
pub(crate) fn from_json<T: DeserializeOwned>(text: &str) -> Result<T, String> {
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path.is_empty() || path == "." {
            inner.to_string()
        } else {
            format!("{path}: {inner}")
        }
    })?;
    de.end().map_err(|e| e.to_string())?;
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::from_json;

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct File {
        items: Vec<Item>,
    }

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Item {
        name: String,
        at: [f32; 3],
    }

    #[test]
    fn errors_name_the_field_and_the_place() {
        let e = from_json::<File>(r#"{"items": [{"name": "a", "at": [1, 2]}]}"#).unwrap_err();
        assert!(e.starts_with("items[0].at: invalid length 2"), "{e}");
        assert!(e.contains("line 1 column"), "{e}");
        let e = from_json::<File>(r#"{"items": [{"name": "a", "at": [1, 2, 3], "x": 1}]}"#)
            .unwrap_err();
        assert!(e.starts_with("items[0].x: unknown field `x`"), "{e}");
        let e = from_json::<File>(r#"{"items": []} trailing"#).unwrap_err();
        assert!(e.contains("trailing"), "{e}");
        assert!(from_json::<File>(r#"{"items": []}"#).is_ok());
    }
}

//! Where a key of a scenario file is and what is wrong with it, worded as
//! the file writes it: the table, the entry, the key and its value.

/// A deserialization error's message on one line, without the backticks
/// serde puts around names.
pub(crate) fn reason(error: &toml::de::Error) -> String {
    error.message().trim().replace('\n', " ").replace('`', "")
}

/// Where a deserialization error is, as the file writes it: the table
/// (`[model.parameters] `), the entry (`joints[2] (revolute): `) and the key
/// with its value (`n = 2.5: `). `table` is the file's table `[within]`
/// (nothing for the whole file).
pub(crate) fn locate(within: &[&str], table: &toml::Table, path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut tables: Vec<String> = within.iter().map(|t| t.to_string()).collect();
    let (mut entry, mut key) = (String::new(), None);
    let mut value = Some(toml::Value::Table(table.clone()));
    for segment in path.iter() {
        let here = value.take();
        match segment {
            Segment::Map { key: k } => {
                value = here.as_ref().and_then(|v| v.get(k)).cloned();
                match &value {
                    Some(toml::Value::Table(_)) if entry.is_empty() => tables.push(k.clone()),
                    Some(toml::Value::Array(_)) if entry.is_empty() => entry.clone_from(k),
                    _ => key = Some(k.clone()),
                }
            }
            Segment::Seq { index } => {
                value = here.as_ref().and_then(|v| v.get(*index)).cloned();
                let kind = value.as_ref().and_then(|v| v.get("kind")).and_then(|k| k.as_str());
                entry = match kind {
                    Some(kind) => format!("{entry}[{index}] ({kind})"),
                    None => format!("{entry}[{index}]"),
                };
            }
            Segment::Enum { .. } | Segment::Unknown => value = here,
        }
    }
    let mut out = String::new();
    if !tables.is_empty() {
        out = format!("[{}] ", tables.join("."));
    }
    if !entry.is_empty() {
        out += &format!("{entry}: ");
    }
    match (key, value) {
        (Some(k), Some(v)) if !v.is_table() && !v.is_array() || v.as_array().is_some_and(|a| a.len() <= 4) => {
            out += &format!("{k} = {v}: ")
        }
        (Some(k), _) => out += &format!("{k}: "),
        _ => {}
    }
    out
}

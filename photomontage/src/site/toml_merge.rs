//! Saving a site without losing what the user wrote around the values: the new content (the
//! site serialised afresh) is merged into the file's previous text with `toml_edit`, so comments,
//! blank lines, key order and the way values were spelled survive wherever the value itself did
//! not change.
//!
//! Rules: a key whose value is unchanged (compared as TOML data, not as text) keeps its text; a
//! changed value takes the new value and keeps the comments around it; keys that are gone are
//! removed (with their comments); new keys are appended to their table. Elements of arrays of
//! tables (`[[photos]]`, `[[control_points]]`, …) are matched by their `id` (observations by
//! photo and point), else by position, so deleting one entry does not move the comments of the
//! others. The caller checks that the merged text reads back to the same site and otherwise
//! writes the plain serialisation.

use toml_edit::{ArrayOfTables, DocumentMut, Item, Table, Value};

/// The `new_text` content laid into the comments and order of `template`; `None` when either
/// does not parse. `reserialise` reads a candidate text and serialises what it read afresh
/// (for a site: parse, then [`super::Site::to_toml`]); with it, keys the template leaves out
/// stay out when reading supplies the same value (serde defaults), so a file that spelled only
/// what differs from the defaults keeps doing so.
#[must_use]
pub fn merge_into_template(
    template: &str,
    new_text: &str,
    reserialise: impl Fn(&str) -> Option<String>,
) -> Option<String> {
    let old: DocumentMut = template.parse().ok()?;
    let new: DocumentMut = new_text.parse().ok()?;
    // First without any key the template lacks; if reading that gives the new content, done.
    let mut minimal = old.clone();
    merge_table(minimal.as_table_mut(), new.as_table(), Absent::Skip);
    let minimal = minimal.to_string();
    let read_back = reserialise(&minimal)?;
    if read_back == new_text {
        return Some(minimal);
    }
    // Else add exactly the absent keys whose defaults differ from the new values.
    let defaults: DocumentMut = read_back.parse().ok()?;
    let mut full = old;
    merge_table(
        full.as_table_mut(),
        new.as_table(),
        Absent::UnlessIn(Some(defaults.as_table())),
    );
    Some(full.to_string())
}

/// What to do with a key the template lacks.
#[derive(Clone, Copy)]
enum Absent<'a> {
    /// Leave it out.
    Skip,
    /// Add it unless this table (what reading the minimal text gave, at the same place) already
    /// holds the same data.
    UnlessIn(Option<&'a Table>),
}

impl<'a> Absent<'a> {
    fn child(self, key: &str) -> Absent<'a> {
        match self {
            Self::Skip => Self::Skip,
            Self::UnlessIn(t) => Self::UnlessIn(t.and_then(|t| t.get(key)?.as_table())),
        }
    }

    fn element(self, key: &str, index: usize) -> Absent<'a> {
        match self {
            Self::Skip => Self::Skip,
            Self::UnlessIn(t) => {
                Self::UnlessIn(t.and_then(|t| t.get(key)?.as_array_of_tables()?.get(index)))
            }
        }
    }
}

fn merge_table(old: &mut Table, new: &Table, absent: Absent<'_>) {
    old.retain(|key, _| new.contains_key(key));
    for (key, new_item) in new.iter() {
        match old.get_mut(key) {
            Some(old_item) => merge_item(old_item, new_item, key, absent),
            None => {
                let add = match absent {
                    Absent::Skip => false,
                    Absent::UnlessIn(reference) => !reference
                        .and_then(|r| r.get(key))
                        .is_some_and(|r| same_item_data(r, new_item)),
                };
                if add {
                    old.insert(key, detached(new_item));
                }
            }
        }
    }
}

fn merge_item(old: &mut Item, new: &Item, key: &str, absent: Absent<'_>) {
    match (old, new) {
        (Item::Table(o), Item::Table(n)) => merge_table(o, n, absent.child(key)),
        (Item::ArrayOfTables(o), Item::ArrayOfTables(n)) => {
            merge_array_of_tables(o, n, key, absent);
        }
        (Item::Value(o), Item::Value(n)) => merge_value(o, n),
        // The user wrote an inline table where the serialiser writes a table section.
        (Item::Value(o @ Value::InlineTable(_)), Item::Table(n)) => {
            merge_value(o, &Value::InlineTable(n.clone().into_inline_table()));
        }
        (old, new) => *old = detached(new),
    }
}

/// Keeps the old text when the value is the same data; else the new value with the old
/// comments around it. Inline tables are merged key by key.
fn merge_value(old: &mut Value, new: &Value) {
    if let (Value::InlineTable(o), Value::InlineTable(n)) = (&mut *old, new) {
        o.retain(|key, _| n.contains_key(key));
        for (key, n_value) in n.iter() {
            match o.get_mut(key) {
                Some(o_value) => merge_value(o_value, n_value),
                None => {
                    o.insert(key, n_value.clone());
                }
            }
        }
        return;
    }
    if same_data(old, new) {
        return;
    }
    let decor = old.decor().clone();
    *old = new.clone();
    *old.decor_mut() = decor;
}

/// Whether two values hold the same TOML data, whatever their spelling.
fn same_data(a: &Value, b: &Value) -> bool {
    let data = |v: &Value| {
        let mut v = v.clone();
        v.decor_mut().clear();
        toml::from_str::<toml::Table>(&format!("v = {v}")).ok()
    };
    matches!((data(a), data(b)), (Some(x), Some(y)) if x == y)
}

/// Whether two items hold the same TOML data, whatever their spelling and layout.
fn same_item_data(a: &Item, b: &Item) -> bool {
    let data = |item: &Item| {
        let mut doc = DocumentMut::new();
        doc.insert("v", detached(item));
        toml::from_str::<toml::Table>(&doc.to_string()).ok()
    };
    matches!((data(a), data(b)), (Some(x), Some(y)) if x == y)
}

/// What identifies an element of an array of tables across saves.
fn element_key(table: &Table) -> Option<String> {
    let text = |k: &str| table.get(k).and_then(Item::as_str).map(str::to_owned);
    text("id").or_else(|| Some(format!("{}\u{0}{}", text("photo")?, text("point")?)))
}

fn merge_array_of_tables(
    old: &mut ArrayOfTables,
    new: &ArrayOfTables,
    key: &str,
    absent: Absent<'_>,
) {
    let keyed = new.iter().all(|t| element_key(t).is_some())
        && old.iter().all(|t| element_key(t).is_some());
    let mut pool: Vec<Option<Table>> = old.iter().cloned().map(Some).collect();
    let mut merged = ArrayOfTables::new();
    let mut first_is_old_first = false;
    for (i, n) in new.iter().enumerate() {
        let found = if keyed {
            let key = element_key(n);
            pool.iter()
                .position(|t| t.as_ref().is_some_and(|t| element_key(t) == key))
        } else {
            (i < pool.len()).then_some(i)
        };
        if i == 0 {
            first_is_old_first = found == Some(0);
        }
        match found.and_then(|j| pool[j].take()) {
            Some(mut o) => {
                merge_table(&mut o, n, absent.element(key, i));
                merged.push(o);
            }
            None => {
                // A new element: written whole (its keys have no old spelling to follow).
                let mut t = n.clone();
                detach_table(&mut t);
                merged.push(t);
            }
        }
    }
    // The comment above the section's first header introduces the section: it stays on top
    // when the first element was deleted or moved.
    if !first_is_old_first && let (Some(o), Some(m)) = (old.get(0), merged.get_mut(0)) {
        let prefix = o.decor().prefix().cloned();
        if let Some(prefix) = prefix {
            m.decor_mut().set_prefix(prefix);
        }
    }
    *old = merged;
}

/// A new item from the fresh serialisation, its table positions cleared so that it is written
/// after its neighbours in the old text rather than where it stood in the new one.
fn detached(item: &Item) -> Item {
    let mut item = item.clone();
    match &mut item {
        Item::Table(t) => detach_table(t),
        Item::ArrayOfTables(a) => a.iter_mut().for_each(detach_table),
        _ => {}
    }
    item
}

fn detach_table(table: &mut Table) {
    table.set_position(None);
    for (_, item) in table.iter_mut() {
        match item {
            Item::Table(t) => detach_table(t),
            Item::ArrayOfTables(a) => a.iter_mut().for_each(detach_table),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OLD: &str = r#"# Site of the new library
schema_version = 1
name = "Library"   # as in the brief

# The camera positions
[[photos]]
id = "A"   # south-west corner
focal = [1.0, 2.0]

[[photos]]
id = "B"
# taken from the roof
focal = [3.0,4.0]

[lighting]
sky_model = "uniform" # overcast day
weights = { sun = 1.0, sky = 2.0 }
"#;

    fn parse(text: &str) -> toml::Table {
        toml::from_str(text).unwrap()
    }

    /// Reading supplies nothing: every key of the new content must be written.
    fn no_defaults(text: &str) -> Option<String> {
        toml::to_string_pretty(&parse(text)).ok()
    }

    /// Reading supplies `colour = "grey"` in every photo that leaves it out.
    fn grey_default(text: &str) -> Option<String> {
        let mut data = parse(text);
        for p in data["photos"].as_array_mut()? {
            p.as_table_mut()?
                .entry("colour")
                .or_insert_with(|| "grey".into());
        }
        toml::to_string_pretty(&data).ok()
    }

    #[test]
    fn unchanged_content_keeps_the_text_byte_for_byte() {
        // The fresh serialisation spells things differently (no comments, other spacing).
        let fresh = toml::to_string_pretty(&parse(OLD)).unwrap();
        assert_ne!(fresh, OLD);
        assert_eq!(merge_into_template(OLD, &fresh, no_defaults).unwrap(), OLD);
    }

    #[test]
    fn changes_keep_comments_order_and_match_elements_by_id() {
        let mut data = parse(OLD);
        data.insert("name".into(), "Library II".into());
        let photos = data["photos"].as_array_mut().unwrap();
        photos.remove(0); // photo A deleted
        photos.push(toml::Value::Table(parse("id = \"C\"\nfocal = [5.0, 6.0]")));
        data["lighting"].as_table_mut().unwrap()["weights"]
            .as_table_mut()
            .unwrap()
            .insert("sky".into(), 2.5.into());
        let fresh = toml::to_string_pretty(&data).unwrap();
        let merged = merge_into_template(OLD, &fresh, no_defaults).unwrap();
        assert_eq!(parse(&merged), data, "{merged}");
        for kept in [
            "# Site of the new library",
            "name = \"Library II\"   # as in the brief",
            "# The camera positions",
            "# taken from the roof\nfocal = [3.0,4.0]",
            "sky_model = \"uniform\" # overcast day",
        ] {
            assert!(merged.contains(kept), "lost {kept:?} in\n{merged}");
        }
        assert!(!merged.contains("south-west corner"), "{merged}");
        let b = merged.find("id = \"B\"").unwrap();
        let c = merged.find("id = \"C\"").unwrap();
        let lighting = merged.find("[lighting]").unwrap();
        assert!(b < c && c < lighting, "{merged}");
    }

    #[test]
    fn keys_left_to_their_defaults_stay_out() {
        let mut data = parse(&grey_default(OLD).unwrap());
        let fresh = toml::to_string_pretty(&data).unwrap();
        assert!(fresh.contains("colour = \"grey\""));
        assert_eq!(merge_into_template(OLD, &fresh, grey_default).unwrap(), OLD);
        // A value away from the default is written, and only there.
        data["photos"].as_array_mut().unwrap()[1]
            .as_table_mut()
            .unwrap()
            .insert("colour".into(), "red".into());
        let fresh = toml::to_string_pretty(&data).unwrap();
        let merged = merge_into_template(OLD, &fresh, grey_default).unwrap();
        assert_eq!(parse(&grey_default(&merged).unwrap()), data, "{merged}");
        assert!(
            merged.contains("colour = \"red\"") && !merged.contains("grey"),
            "{merged}"
        );
    }

    #[test]
    fn unparsable_input_gives_none() {
        assert!(merge_into_template("a = [", "a = 1", no_defaults).is_none());
        assert!(merge_into_template("a = 1", "a = [", no_defaults).is_none());
    }
}

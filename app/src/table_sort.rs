//! Sortable tables: a click on a column header sorts the rows by that column, a second click
//! reverses the order, a third restores the file's order. The state lives in egui's memory under
//! the table's id, so any table (residuals, samples, horizon samples) gets it without fields of its
//! own; the order itself is computed by [`sorted_rows`], a pure function with unit tests.

use std::cmp::Ordering;

use eframe::egui;

/// One cell's sort key: numbers compare as numbers (NaN last), text case-insensitively with the
/// exact text as tie-break.
#[derive(Debug, Clone, PartialEq)]
pub enum SortKey {
    Number(f64),
    Text(String),
}

impl SortKey {
    fn compare(&self, other: &Self) -> Ordering {
        match (self, other) {
            (Self::Number(a), Self::Number(b)) => match (a.is_nan(), b.is_nan()) {
                (true, true) => Ordering::Equal,
                (true, false) => Ordering::Greater,
                (false, true) => Ordering::Less,
                (false, false) => a.total_cmp(b),
            },
            (Self::Text(a), Self::Text(b)) => a
                .to_lowercase()
                .cmp(&b.to_lowercase())
                .then_with(|| a.cmp(b)),
            // Mixed kinds in one column: numbers first.
            (Self::Number(_), Self::Text(_)) => Ordering::Less,
            (Self::Text(_), Self::Number(_)) => Ordering::Greater,
        }
    }
}

/// Which column a table is sorted by, if any.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SortState {
    /// Column index, `None` for the file's order.
    pub column: Option<usize>,
    pub descending: bool,
}

impl SortState {
    /// The state after a click on column `column`'s header: ascending, then descending, then
    /// unsorted.
    #[must_use]
    pub fn clicked(self, column: usize) -> Self {
        match self.column {
            Some(c) if c == column && !self.descending => Self {
                column: Some(column),
                descending: true,
            },
            Some(c) if c == column => Self::default(),
            _ => Self {
                column: Some(column),
                descending: false,
            },
        }
    }

    /// The header's text with the direction arrow of the sorted column.
    #[must_use]
    pub fn header_text(self, column: usize, title: &str) -> String {
        match self.column {
            Some(c) if c == column && self.descending => format!("{title} (desc)"),
            Some(c) if c == column => format!("{title} (asc)"),
            _ => title.to_owned(),
        }
    }

    /// The state stored for table `id` (unsorted when none).
    #[must_use]
    pub fn load(ui: &egui::Ui, id: egui::Id) -> Self {
        ui.data(|d| d.get_temp::<SortStateData>(id))
            .map_or_else(Self::default, |d| d.0)
    }

    /// Stores the state for table `id`.
    pub fn store(self, ui: &egui::Ui, id: egui::Id) {
        ui.data_mut(|d| d.insert_temp(id, SortStateData(self)));
    }
}

#[derive(Clone, Copy)]
struct SortStateData(SortState);

/// Row indices in display order: `key(row, column)` gives each cell's key; rows with equal keys
/// keep the file's order (stable), and the file's order is kept when no column is chosen.
pub fn sorted_rows<T>(
    rows: &[T],
    state: SortState,
    key: impl Fn(&T, usize) -> SortKey,
) -> Vec<usize> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    if let Some(column) = state.column {
        let keys: Vec<SortKey> = rows.iter().map(|r| key(r, column)).collect();
        order.sort_by(|&a, &b| {
            let o = keys[a].compare(&keys[b]);
            if state.descending { o.reverse() } else { o }
        });
    }
    order
}

/// A clickable column header of table `table`; returns the new state when it was clicked. Named
/// "sort `table` by `title`", with " (ascending)" or " (descending)" when the table is sorted by it, for tests and
/// screen readers.
pub fn header(
    ui: &mut egui::Ui,
    table: &str,
    state: SortState,
    column: usize,
    title: &str,
) -> Option<SortState> {
    let r = ui
        .add(
            egui::Button::new(egui::RichText::new(state.header_text(column, title)).strong())
                .frame(false),
        )
        .on_hover_text("click to sort; again to reverse; a third time for the file's order");
    let direction = match state.column {
        Some(c) if c == column && state.descending => " (descending)",
        Some(c) if c == column => " (ascending)",
        _ => "",
    };
    crate::widgets::name_widget(ui, &r, &format!("sort {table} by {title}{direction}"));
    r.clicked().then(|| state.clicked(column))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows() -> Vec<(&'static str, f64)> {
        vec![("b", 2.0), ("A", f64::NAN), ("c", -1.0), ("a", 2.0)]
    }

    fn key(r: &(&'static str, f64), c: usize) -> SortKey {
        if c == 0 {
            SortKey::Text(r.0.to_owned())
        } else {
            SortKey::Number(r.1)
        }
    }

    #[test]
    fn clicks_cycle_ascending_descending_unsorted() {
        let s = SortState::default().clicked(1);
        assert_eq!(
            s,
            SortState {
                column: Some(1),
                descending: false
            }
        );
        let s = s.clicked(1);
        assert_eq!(
            s,
            SortState {
                column: Some(1),
                descending: true
            }
        );
        assert_eq!(s.clicked(1), SortState::default());
        // Another column starts ascending again.
        assert_eq!(
            s.clicked(0),
            SortState {
                column: Some(0),
                descending: false
            }
        );
        assert_eq!(s.header_text(1, "|v| px"), "|v| px (desc)");
        assert_eq!(s.header_text(0, "point"), "point");
    }

    #[test]
    fn numbers_sort_with_nan_last_and_ties_in_file_order() {
        let up = SortState {
            column: Some(1),
            descending: false,
        };
        assert_eq!(sorted_rows(&rows(), up, key), [2, 0, 3, 1]);
        let down = SortState {
            column: Some(1),
            descending: true,
        };
        // Reversed comparison: NaN first, equal keys keep the file's order (stable sort).
        assert_eq!(sorted_rows(&rows(), down, key), [1, 0, 3, 2]);
        assert_eq!(
            sorted_rows(&rows(), SortState::default(), key),
            [0, 1, 2, 3]
        );
    }

    #[test]
    fn text_sorts_case_insensitively_with_exact_tie_break() {
        let up = SortState {
            column: Some(0),
            descending: false,
        };
        // "A" < "a" by the exact tie-break, both before "b".
        assert_eq!(sorted_rows(&rows(), up, key), [1, 3, 0, 2]);
    }
}

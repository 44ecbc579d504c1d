//! What a primary click on the photo does on the Points and Solve tabs. Placing an observation is
//! an explicit mode: choosing a point (in the table, the tie-point list or "Pick id") *arms* it,
//! the next click on the photo places it and disarms it, Escape disarms it. A click on an existing
//! mark selects that mark's point and never moves another point's observation there; a click on
//! empty photo with nothing armed does nothing.

/// Outcome of a click on the photo.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PhotoClick {
    /// Put the armed point's observation at the click, then disarm.
    Place(String),
    /// Select the point whose mark was clicked (disarms any armed point).
    Select(String),
    /// Nothing armed and no mark hit.
    Ignore,
}

/// Decides a click from the armed point and the point whose mark lies under the cursor (within the
/// grab radius), if any.
#[must_use]
pub fn photo_click(armed: Option<&str>, mark_under_cursor: Option<&str>) -> PhotoClick {
    match (mark_under_cursor, armed) {
        (Some(hit), _) => PhotoClick::Select(hit.to_owned()),
        (None, Some(point)) => PhotoClick::Place(point.to_owned()),
        (None, None) => PhotoClick::Ignore,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_click_on_a_mark_selects_it_and_never_moves_the_armed_point() {
        assert_eq!(
            photo_click(Some("P1"), Some("P7")),
            PhotoClick::Select("P7".into())
        );
        assert_eq!(
            photo_click(None, Some("P7")),
            PhotoClick::Select("P7".into())
        );
    }

    #[test]
    fn only_an_armed_point_is_placed() {
        assert_eq!(
            photo_click(Some("P1"), None),
            PhotoClick::Place("P1".into())
        );
        assert_eq!(photo_click(None, None), PhotoClick::Ignore);
    }
}

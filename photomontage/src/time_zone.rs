//! Civil time in a named time zone: a site's `[location] time_zone` (an IANA tz database name such
//! as `Europe/Zurich`) turns local clock times without a UTC offset — EXIF `DateTimeOriginal`
//! without `OffsetTimeOriginal`, the `--times` of a sun study — into instants the SPA can use.
//!
//! The rules come from the IANA time zone database (Eggert & Olson, tz; RFC 6557), compiled into
//! the program by `chrono-tz`, so the answer does not depend on the machine's `/usr/share/zoneinfo`.
//! Daylight saving time is applied: in the hour the clocks go back a local time happens twice
//! (ambiguous), in the hour they go forward it does not happen at all (skipped); both are errors,
//! never a silent guess, because a one-hour error moves the sun by about 15° of azimuth.
//!
//! Known limitations: the database is the one `chrono-tz` was built with (rule changes after that
//! release are not known); times before 1970 follow the database's best-effort history.

use chrono::{DateTime, FixedOffset, LocalResult, NaiveDateTime, TimeZone as _};
use chrono_tz::Tz;

/// Most edits (Levenshtein distance) for a zone name to be offered as "did you mean".
const MAX_HINT_EDITS: usize = 4;

/// What can go wrong turning a local time into an instant.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TimeZoneError {
    #[error("`{name}` is not an IANA time zone name (e.g. Europe/Zurich){}",
        hint.as_ref().map(|h| format!("; did you mean `{h}`?")).unwrap_or_default())]
    UnknownZone { name: String, hint: Option<String> },
    #[error(
        "local time {local} happens twice in {zone} (the clocks go back): it could be {earlier} \
         or {later}; give the time with its UTC offset"
    )]
    Ambiguous {
        local: String,
        zone: String,
        earlier: String,
        later: String,
    },
    #[error(
        "local time {local} does not exist in {zone} (the clocks go forward over it); give the \
         time with its UTC offset"
    )]
    Skipped { local: String, zone: String },
}

/// A validated IANA time zone (the site's `location.time_zone`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SiteTimeZone(Tz);

impl SiteTimeZone {
    /// Parses an IANA name (exact spelling, as the tz database has it).
    ///
    /// # Errors
    /// [`TimeZoneError::UnknownZone`] with the closest known name as a hint when one is near.
    pub fn parse(name: &str) -> Result<Self, TimeZoneError> {
        name.trim()
            .parse::<Tz>()
            .map(Self)
            .map_err(|_| TimeZoneError::UnknownZone {
                name: name.to_owned(),
                hint: closest_zone_name(name),
            })
    }

    /// The IANA name.
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.0.name()
    }

    /// The instant of local clock time `local` in this zone, with the offset in force then.
    ///
    /// # Errors
    /// [`TimeZoneError::Ambiguous`] when the local time happens twice,
    /// [`TimeZoneError::Skipped`] when it does not happen.
    pub fn resolve(&self, local: NaiveDateTime) -> Result<DateTime<FixedOffset>, TimeZoneError> {
        let text = || local.format("%Y-%m-%dT%H:%M:%S").to_string();
        match self.0.from_local_datetime(&local) {
            LocalResult::Single(t) => Ok(t.fixed_offset()),
            LocalResult::Ambiguous(a, b) => Err(TimeZoneError::Ambiguous {
                local: text(),
                zone: self.name().to_owned(),
                earlier: a.fixed_offset().to_rfc3339(),
                later: b.fixed_offset().to_rfc3339(),
            }),
            LocalResult::None => Err(TimeZoneError::Skipped {
                local: text(),
                zone: self.name().to_owned(),
            }),
        }
    }

    /// `instant` as this zone's clock shows it (with the offset in force then).
    #[must_use]
    pub fn to_local(&self, instant: &DateTime<FixedOffset>) -> DateTime<FixedOffset> {
        instant.with_timezone(&self.0).fixed_offset()
    }
}

/// The known zone name closest to `name` (case-insensitive edit distance), when one is near.
fn closest_zone_name(name: &str) -> Option<String> {
    let wanted = name.trim().to_ascii_lowercase();
    chrono_tz::TZ_VARIANTS
        .iter()
        .map(|tz| {
            (
                edit_distance(&wanted, &tz.name().to_ascii_lowercase()),
                tz.name(),
            )
        })
        .filter(|(d, _)| *d <= MAX_HINT_EDITS)
        .min_by_key(|(d, n)| (*d, *n))
        .map(|(_, n)| n.to_owned())
}

/// Levenshtein distance over bytes (zone names are ASCII).
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let mut previous: Vec<usize> = (0..=b.len()).collect();
    let mut current = vec![0; b.len() + 1];
    for (i, ca) in a.iter().enumerate() {
        current[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitution = previous[j] + usize::from(ca != cb);
            current[j + 1] = substitution.min(previous[j + 1] + 1).min(current[j] + 1);
        }
        std::mem::swap(&mut previous, &mut current);
    }
    previous[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn local(text: &str) -> NaiveDateTime {
        NaiveDateTime::parse_from_str(text, "%Y-%m-%dT%H:%M").unwrap()
    }

    #[test]
    fn summer_time_in_zurich_is_utc_plus_two() {
        let zurich = SiteTimeZone::parse("Europe/Zurich").unwrap();
        let t = zurich.resolve(local("2024-06-21T15:00")).unwrap();
        assert_eq!(t.to_utc().to_rfc3339(), "2024-06-21T13:00:00+00:00");
        assert_eq!(t.to_rfc3339(), "2024-06-21T15:00:00+02:00");
    }

    #[test]
    fn winter_time_in_zurich_is_utc_plus_one() {
        let zurich = SiteTimeZone::parse("Europe/Zurich").unwrap();
        let t = zurich.resolve(local("2024-01-15T15:00")).unwrap();
        assert_eq!(t.to_utc().to_rfc3339(), "2024-01-15T14:00:00+00:00");
    }

    #[test]
    fn southern_hemisphere_summer_is_in_january() {
        // Sydney: AEDT (+11) in January, AEST (+10) in July.
        let sydney = SiteTimeZone::parse("Australia/Sydney").unwrap();
        let jan = sydney.resolve(local("2024-01-15T12:00")).unwrap();
        let jul = sydney.resolve(local("2024-07-15T12:00")).unwrap();
        assert_eq!(jan.offset().local_minus_utc(), 11 * 3600);
        assert_eq!(jul.offset().local_minus_utc(), 10 * 3600);
    }

    #[test]
    fn the_skipped_hour_is_an_error() {
        // 2024-03-31: Central European clocks jump from 02:00 to 03:00.
        let zurich = SiteTimeZone::parse("Europe/Zurich").unwrap();
        let e = zurich.resolve(local("2024-03-31T02:30")).unwrap_err();
        assert!(matches!(e, TimeZoneError::Skipped { .. }), "{e}");
        assert!(e.to_string().contains("2024-03-31T02:30:00"), "{e}");
    }

    #[test]
    fn the_repeated_hour_is_an_error_naming_both_instants() {
        // 2024-10-27: clocks go back from 03:00 CEST to 02:00 CET.
        let zurich = SiteTimeZone::parse("Europe/Zurich").unwrap();
        let e = zurich.resolve(local("2024-10-27T02:30")).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("+02:00") && text.contains("+01:00"), "{text}");
    }

    #[test]
    fn an_unknown_name_gets_a_close_hint() {
        let e = SiteTimeZone::parse("Europe/Zurik").unwrap_err();
        assert_eq!(
            e,
            TimeZoneError::UnknownZone {
                name: "Europe/Zurik".into(),
                hint: Some("Europe/Zurich".into())
            }
        );
        assert!(e.to_string().contains("did you mean `Europe/Zurich`"));
        let far = SiteTimeZone::parse("Mars/Olympus_Mons").unwrap_err();
        assert!(
            matches!(far, TimeZoneError::UnknownZone { hint: None, .. }),
            "{far}"
        );
    }

    #[test]
    fn edit_distance_known_values() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
    }
}

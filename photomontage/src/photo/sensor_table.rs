//! Sensor sizes of camera bodies whose EXIF gives the focal length in millimetres but no usable
//! focal-plane resolution, and the robust matching of EXIF `Make`/`Model` strings against them.
//!
//! Sizes come from the manufacturers' specification sheets; compacts whose sheets give only the
//! optical-format "type" (1/2.5″, 1/1.8″, 2/3″ …) use the customary active-area dimensions of
//! that type (1/2.5″: 5.76 × 4.29 mm, 1/2.3″: 6.17 × 4.55 mm, 1/1.8″: 7.18 × 5.32 mm,
//! 1/1.7″: 7.44 × 5.58 mm, 1/2″: 6.4 × 4.8 mm, 2/3″: 8.8 × 6.6 mm, 1/3.2″: 4.54 × 3.42 mm).
//!
//! Matching: makers write the same company as `NIKON CORPORATION`, `Nikon Corporation`,
//! `PENTAX Corporation `, `OLYMPUS IMAGING CORP.`, `EASTMAN KODAK COMPANY`; models repeat the
//! make (`PENTAX K10D`, `Canon EOS 40D`) or carry decorations (`<Digimax i50 MP3, Samsung #1
//! MP3>`). Both are lower-cased, stripped of punctuation and company words, blanks collapsed,
//! the make's words removed from the front of the model, and only then compared.
//!
//! # Known limitations
//! The table is short (the bodies of the project's sample data and a few common ones); the
//! optical-format dimensions are nominal and can be a few per cent off a given sensor.

/// (make word, normalised model, sensor width mm, sensor height mm).
const SENSOR_SIZES_MM: &[(&str, &str, f64, f64)] = &[
    ("apple", "iphone 4s", 4.54, 3.42),
    ("canon", "eos 40d", 22.2, 14.8),
    ("canon", "eos 450d", 22.2, 14.8),
    ("canon", "eos 5d mark ii", 36.0, 24.0),
    ("canon", "powershot s40", 7.18, 5.32),
    ("canon", "powershot sx60 hs", 6.17, 4.55),
    ("fujifilm", "finepix e500", 5.76, 4.29),
    ("kodak", "cx7530 zoom digital camera", 5.76, 4.29),
    ("nikon", "coolpix p6000", 7.44, 5.58),
    ("nikon", "d70", 23.7, 15.6),
    ("nikon", "d700", 36.0, 23.9),
    ("nikon", "e950", 6.4, 4.8),
    ("olympus", "c8080wz", 8.8, 6.6),
    ("panasonic", "dmc-fz30", 7.18, 5.32),
    ("pentax", "k10d", 23.5, 15.7),
    ("samsung", "digimax i50 mp3", 5.76, 4.29),
    ("sony", "ilce-7m3", 35.6, 23.8),
];

/// Words that name the kind of company, not the maker.
const COMPANY_WORDS: &[&str] = &[
    "corporation",
    "corp",
    "co",
    "ltd",
    "company",
    "inc",
    "imaging",
    "optical",
    "eastman",
    "techwin",
    "digital",
];

fn words(text: &str) -> Vec<String> {
    text.to_lowercase()
        .replace(['<', '>', '.', ','], " ")
        .split_whitespace()
        .map(str::to_owned)
        .collect()
}

/// The maker's words of an EXIF `Make`, company words removed (`NIKON CORPORATION` → `nikon`).
#[must_use]
pub fn normalised_make(make: &str) -> String {
    words(make)
        .into_iter()
        .filter(|w| !COMPANY_WORDS.contains(&w.as_str()))
        .collect::<Vec<_>>()
        .join(" ")
}

/// An EXIF `Model` normalised for matching: lower case, blanks collapsed, anything after a
/// comma dropped, and the make's words removed from the front (`PENTAX K10D` → `k10d`).
#[must_use]
pub fn normalised_model(make: &str, model: &str) -> String {
    let first_part = model.split(',').next().unwrap_or(model);
    let make_words: Vec<String> = words(make);
    let mut model_words = words(first_part);
    while model_words
        .first()
        .is_some_and(|w| make_words.contains(w) || COMPANY_WORDS.contains(&w.as_str()))
    {
        model_words.remove(0);
    }
    model_words.join(" ")
}

/// Sensor width and height (mm) of a camera named by its EXIF `Make` and `Model`.
#[must_use]
pub fn sensor_size_mm(make: Option<&str>, model: Option<&str>) -> Option<[f64; 2]> {
    let model = model?;
    let make = make.unwrap_or("");
    let make_norm = normalised_make(make);
    let model_norm = normalised_model(make, model);
    SENSOR_SIZES_MM
        .iter()
        .find(|(m, name, _, _)| {
            let make_ok = make_norm.is_empty() || make_norm.split(' ').any(|w| w == *m);
            // Without a make, the model must carry it (`Canon EOS 40D`).
            let model_ok = *name == model_norm
                || normalised_model(m, &model_norm) == *name
                || (make_norm.is_empty() && normalised_model(m, model) == *name);
            make_ok && model_ok
        })
        .map(|&(_, _, w, h)| [w, h])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn makers_spell_themselves_many_ways() {
        let k10d = Some([23.5, 15.7]);
        for make in [
            "PENTAX Corporation",
            "PENTAX CORPORATION ",
            "pentax",
            "Pentax Corp.",
        ] {
            assert_eq!(
                sensor_size_mm(Some(make), Some("PENTAX K10D  ")),
                k10d,
                "{make}"
            );
            assert_eq!(sensor_size_mm(Some(make), Some("K10D")), k10d, "{make}");
        }
        assert_eq!(
            sensor_size_mm(Some("NIKON CORPORATION"), Some("NIKON D70")),
            Some([23.7, 15.6])
        );
        assert_eq!(
            sensor_size_mm(Some("OLYMPUS IMAGING CORP."), Some("C8080WZ")),
            Some([8.8, 6.6])
        );
        assert_eq!(
            sensor_size_mm(
                Some("SAMSUNG TECHWIN"),
                Some("<Digimax i50 MP3, Samsung #1 MP3>")
            ),
            Some([5.76, 4.29])
        );
        assert_eq!(
            sensor_size_mm(None, Some("Canon EOS 40D")),
            Some([22.2, 14.8])
        );
        // A Nikon D70 is not a D700, and a maker's model under another make is no match.
        assert_eq!(
            sensor_size_mm(Some("Nikon"), Some("D700")),
            Some([36.0, 23.9])
        );
        assert_eq!(sensor_size_mm(Some("Canon"), Some("D70")), None);
        assert_eq!(sensor_size_mm(Some("Nikon"), None), None);
    }
}

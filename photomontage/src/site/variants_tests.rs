#![allow(clippy::float_cmp)] // placements and reflectances are copied, not computed: exact

use std::path::Path;

use super::*;
use crate::site::site_scene::{ObjectSource, site_scene};
use crate::site::{CadModel, ModelUnits, ModelUpAxis, Placement, VariantPlacement};

const BOX_OBJ: &str = "mtllib box.mtl\nusemtl black\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// Reflectance of the red material a variant assigns (a value no file in the fixture has).
const RED: [f64; 3] = [0.8, 0.1, 0.05];

fn model(id: &str) -> CadModel {
    CadModel {
        id: id.into(),
        file: "box.obj".into(),
        units: ModelUnits::default(),
        up_axis: ModelUpAxis::default(),
        placement: Placement::default(),
        visible: true,
    }
}

/// Two models of the same box, "a" at the origin and "b" 5 m east; variant "only_b" shows b
/// moved 10 m north and painted red, "hidden" shows nothing.
fn doc_in(dir: &Path) -> SiteDocument {
    std::fs::write(dir.join("box.obj"), BOX_OBJ).unwrap();
    std::fs::write(dir.join("box.mtl"), "newmtl black\nKd 0 0 0\n").unwrap();
    let mut b = model("b");
    b.placement.translation = [5.0, 0.0, 0.0];
    let mut only_b = Variant::named("only_b");
    only_b.visible_models = Some(vec!["b".into()]);
    only_b.placements.push(VariantPlacement {
        model: "b".into(),
        placement: Placement {
            translation: [5.0, 10.0, 0.0],
            ..Placement::default()
        },
    });
    only_b
        .materials
        .push(crate::scene::Material::diffuse("black", RED));
    let mut hidden = Variant::named("hidden");
    hidden.visible_models = Some(Vec::new());
    let site = Site {
        models: vec![model("a"), b],
        variants: vec![only_b, hidden],
        ..Site::default()
    };
    SiteDocument {
        path: dir.join("site.toml"),
        site,
    }
}

#[test]
fn a_variant_sets_visibility_placement_and_materials() {
    let dir = tempfile::tempdir().unwrap();
    let doc = doc_in(dir.path());
    let v = variant_document(&doc, Some("only_b")).unwrap();
    assert!(!v.site.models[0].visible);
    assert!(v.site.models[1].visible);
    assert_eq!(v.site.models[1].placement.translation, [5.0, 10.0, 0.0]);
    // Everything else is the site's.
    assert_eq!(v.site.lighting, doc.site.lighting);
    assert_eq!(v.site.render, doc.site.render);
    assert_eq!(v.site.variants.len(), 1);
    assert!(v.site.variants[0].applied);

    let base = site_scene(&doc).unwrap();
    assert_eq!(
        base.object_sources,
        [
            ObjectSource::Model("a".into()),
            ObjectSource::Model("b".into())
        ]
    );
    let black = |s: &crate::scene::Scene| {
        s.materials()
            .iter()
            .find(|m| m.name == "black")
            .unwrap()
            .diffuse_rgb
    };
    assert_eq!(black(&base.scene), [0.0; 3]);

    let scene = site_scene(&v).unwrap();
    assert_eq!(scene.object_sources, [ObjectSource::Model("b".into())]);
    assert_eq!(black(&scene.scene), RED);
    // The box's lowest corner moved to the variant's translation.
    let [lo, _] = scene.scene.bounding_box_in_world_m().unwrap();
    assert_eq!([lo.x, lo.y, lo.z], [5.0, 10.0, 0.0]);

    let none = site_scene(&variant_document(&doc, Some("hidden")).unwrap()).unwrap();
    assert!(none.object_sources.is_empty());
    // No variant: the site as it is.
    assert_eq!(variant_document(&doc, None).unwrap(), doc);
}

#[test]
fn a_variant_naming_a_removed_model_is_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = doc_in(dir.path());
    doc.site.models.retain(|m| m.id != "b");
    let e = variant_document(&doc, Some("only_b")).unwrap_err();
    let text = e.to_string();
    assert!(
        matches!(&e, VariantError::UnknownModel { variant, model, field: "visible_models", .. }
            if variant == "only_b" && model == "b"),
        "{text}"
    );
    assert!(text.contains("`only_b`") && text.contains("`b`"), "{text}");
    // The other variant still applies; the site itself still validates (nothing is lost).
    assert!(variant_document(&doc, Some("hidden")).is_ok());
    assert!(doc.site.validate().is_empty());
    // A placement of an unknown model is named too.
    doc.site.variants[1].placements.push(VariantPlacement {
        model: "gone".into(),
        placement: Placement::default(),
    });
    let text = variant_document(&doc, Some("hidden"))
        .unwrap_err()
        .to_string();
    assert!(
        text.contains("placements") && text.contains("`gone`"),
        "{text}"
    );
}

#[test]
fn unknown_and_duplicate_names_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = doc_in(dir.path());
    let text = variant_document(&doc, Some("tall"))
        .unwrap_err()
        .to_string();
    assert!(
        text.contains("`tall`") && text.contains("only_b, hidden"),
        "{text}"
    );
    let twice = ["hidden".to_owned(), "hidden".to_owned()];
    assert!(matches!(
        checked_variant_names(&doc.site, Some(&twice)),
        Err(VariantError::DuplicateName { .. })
    ));
    assert_eq!(
        checked_variant_names(&doc.site, None).unwrap(),
        ["only_b", "hidden"]
    );
    doc.site.variants.push(Variant::named("hidden"));
    let issues = doc.site.validate();
    assert_eq!(issues.len(), 1, "{issues:?}");
    assert_eq!(issues[0].field, "variants[2].name");
    assert!(issues[0].message.contains("`hidden`"));
    doc.site.variants.truncate(2);
    doc.site.variants.clear();
    assert!(matches!(
        checked_variant_names(&doc.site, None),
        Err(VariantError::NoVariants)
    ));
}

#[test]
fn variants_round_trip_through_the_site_file_and_bad_ones_name_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let doc = doc_in(dir.path());
    let text = toml::to_string(&doc.site).unwrap();
    let back = Site::from_toml(&text, Path::new("site.toml")).unwrap();
    assert_eq!(back.variants, doc.site.variants);

    let bad = format!("{text}\n[[variants]]\nname = \"only_b\"\n");
    let e = Site::from_toml(&bad, Path::new("site.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("variants[2].name") && e.contains("`only_b`"),
        "{e}"
    );
    let bad = format!(
        "{text}\n[[variants]]\nname = \"neg\"\n[[variants.materials]]\nname = \"x\"\ndiffuse_rgb = [1.5, 0.0, 0.0]\n"
    );
    let e = Site::from_toml(&bad, Path::new("site.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("variants[2].materials[0]") && e.contains("`neg`"),
        "{e}"
    );
}

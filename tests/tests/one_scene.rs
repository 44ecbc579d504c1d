//! Issue 13 item 1, "one scene for everything": on every sample site, the natural scene is the
//! same from every caller. The renderer, the radiosity CLI and the studio build it through
//! `site::site_scene::site_scene` (which adds the CAD models after it), the fits through
//! `fit::natural_scene::natural_scene` itself, the photo picker through `PolygonPicker::new`:
//! same triangles (bit-identical vertices), same materials, same objects, same polygon of every
//! triangle.

use std::path::{Path, PathBuf};

use photomontage::fit::natural_scene::natural_scene;
use photomontage::fit::pick::PolygonPicker;
use photomontage::scene::ObjectKind;
use photomontage::site::SiteDocument;
use photomontage::site::site_scene::{ObjectSource, site_material_library, site_scene};

fn sample_sites() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sample_sites");
    let mut sites: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("sample_sites")
        .map(|e| e.expect("entry").path().join("site.toml"))
        .filter(|p| p.is_file())
        .collect();
    sites.sort();
    assert!(!sites.is_empty(), "no sample site under {}", root.display());
    sites
}

#[test]
fn every_caller_builds_the_same_natural_scene() {
    for path in sample_sites() {
        let label = path.display().to_string();
        let doc = SiteDocument::load(&path).expect(&label);
        let library = site_material_library(&doc).expect(&label);
        let fits = natural_scene(&doc.site, library.as_ref()).expect(&label);
        assert!(fits.skipped.is_empty(), "{label}: {:?}", fits.skipped);
        let render = site_scene(&doc).expect(&label);
        let picker = PolygonPicker::new(&doc.site, library.as_ref()).expect(&label);

        let natural = fits.scene.triangles();
        assert!(!natural.is_empty(), "{label}: no natural triangles");
        println!(
            "{label}: {} natural triangles, {} objects; renderer adds {} triangles",
            natural.len(),
            fits.scene.objects().len(),
            render.scene.triangles().len() - natural.len()
        );
        // The renderer's scene starts with exactly the natural scene …
        assert_eq!(
            &render.scene.triangles()[..natural.len()],
            natural,
            "{label}"
        );
        let n_objects = fits.scene.objects().len();
        assert_eq!(
            &render.scene.objects()[..n_objects],
            fits.scene.objects(),
            "{label}"
        );
        let n_materials = fits.scene.materials().len();
        assert_eq!(
            &render.scene.materials()[..n_materials],
            fits.scene.materials(),
            "{label}"
        );
        // … and everything after it is artificial (the CAD models).
        for t in &render.scene.triangles()[natural.len()..] {
            assert_eq!(
                render.scene.objects()[t.object.0 as usize].kind,
                ObjectKind::Artificial,
                "{label}"
            );
        }
        // Same polygon for every triangle: the fits' index, the picker's, and the renderer's
        // object sources.
        assert_eq!(
            picker.polygon_of_triangle(),
            fits.polygon_of_triangle.as_slice()
        );
        for (t, &poly) in natural.iter().zip(&fits.polygon_of_triangle) {
            let id = &doc.site.polygons[poly].id;
            assert_eq!(
                render.object_sources[t.object.0 as usize],
                ObjectSource::Polygon(id.clone()),
                "{label}"
            );
            assert_eq!(&fits.scene.objects()[t.object.0 as usize].name, id);
        }
    }
}

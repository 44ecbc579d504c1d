//! Render farms through the CLI (issue 18) on the small test site, 96 × 256 px (8 rows of
//! 32-px render tiles): `render --tile I/N` + `merge` and `jobs` + `run-job` give files
//! byte-identical to the whole-image render; a finished job is skipped; bad tiles, merges,
//! job indexes and a site changed under a job list are refused with clear messages.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const TALL_PX: [u32; 2] = [96, 256];

fn pm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(args)
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "failed: {}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn fails(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "should fail with `{needle}`");
    assert!(err.contains(needle), "`{needle}` not in: {err}");
}

fn tall_site(dir: &Path) -> PathBuf {
    common::make_site_sized(dir, TALL_PX)
}

#[test]
fn tiles_rendered_alone_and_merged_equal_the_whole_render_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let site = tall_site(dir.path());
    let d = |name: &str| dir.path().join(name);
    for (ext, layers) in [
        ("exr", "depth,object_id,shadow_change"),
        ("png", ""),
        ("tif", ""),
    ] {
        let whole = d(&format!("whole.{ext}"));
        let mut args = vec!["render", s(&site), "--view", "p1", "--out", s(&whole)];
        if !layers.is_empty() {
            args.extend(["--layers", layers]);
        }
        ok(&pm(&args));
        for count in [1_u32, 4, 7] {
            let mut parts = Vec::new();
            for i in 1..=count {
                let part = d(&format!("part-{ext}-{i}-of-{count}.exr"));
                let tile = format!("{i}/{count}");
                let mut args = vec![
                    "render",
                    s(&site),
                    "--view",
                    "p1",
                    "--tile",
                    &tile,
                    "--out",
                    s(&part),
                ];
                if !layers.is_empty() {
                    args.extend(["--layers", layers]);
                }
                let out = ok(&pm(&args));
                assert!(out.contains(&format!("tile {tile}")), "{out}");
                parts.push(part);
            }
            let merged = d(&format!("merged-{count}.{ext}"));
            let mut args = vec!["merge"];
            args.extend(parts.iter().rev().map(|p| s(p)));
            args.extend(["--out", s(&merged)]);
            ok(&pm(&args));
            assert_eq!(
                std::fs::read(&merged).unwrap(),
                std::fs::read(&whole).unwrap(),
                "{count} tiles merged into .{ext}"
            );
            // The view geometry travels through the parts into the merged file: EXIF and XMP
            // in PNG and TIFF, header attributes in EXR.
            let bytes = std::fs::read(&merged).unwrap();
            let has = |needle: &[u8]| bytes.windows(needle.len()).any(|w| w == needle);
            match ext {
                "png" => assert!(has(b"eXIf") && has(b"XML:com.adobe.xmp"), "PNG EXIF, XMP"),
                "tif" => assert!(has(b"urn:photomontage:view:1.0/"), "TIFF XMP"),
                _ => assert!(
                    has(b"photomontage.view") && has(b"software"),
                    "EXR attributes"
                ),
            }
            if ext == "exr" {
                let table = |p: &Path| std::fs::read(p.with_extension("objects.json")).unwrap();
                assert_eq!(table(&merged), table(&whole));
            }
        }
    }
}

#[test]
fn a_job_list_runs_idempotently_and_merges_into_the_whole_render() {
    let dir = tempfile::tempdir().unwrap();
    let site = tall_site(dir.path());
    let whole = dir.path().join("whole.exr");
    ok(&pm(&[
        "render",
        s(&site),
        "--view",
        "p1",
        "--out",
        s(&whole),
    ]));
    let list = dir.path().join("farm/jobs.json");
    let out = ok(&pm(&[
        "jobs",
        s(&site),
        "--views",
        "p1",
        "--tiles",
        "3",
        "--out",
        s(&list),
    ]));
    assert!(out.contains("3 jobs"), "{out}");
    // Paths in the list are relative to its folder.
    let text = std::fs::read_to_string(&list).unwrap();
    assert!(text.contains("\"site\": \"../site.toml\""), "{text}");
    // Merging before every job ran names the missing tiles.
    fails(
        &pm(&["run-job", s(&list), "--merge"]),
        "missing tiles 1, 2, 3 of 3",
    );
    for k in ["2", "0", "1"] {
        let out = ok(&pm(&["run-job", s(&list), "--index", k, "--threads", "1"]));
        assert!(out.contains("rendered"), "{out}");
    }
    let before = std::fs::metadata(dir.path().join("farm/parts/p1.tile-2-of-3.exr"))
        .unwrap()
        .modified()
        .unwrap();
    let out = ok(&pm(&["run-job", s(&list), "--index", "1"]));
    assert!(out.contains("already complete; skipped"), "{out}");
    let after = std::fs::metadata(dir.path().join("farm/parts/p1.tile-2-of-3.exr"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(before, after, "a finished part is not rewritten");
    ok(&pm(&["run-job", s(&list), "--merge"]));
    assert_eq!(
        std::fs::read(dir.path().join("farm/p1.exr")).unwrap(),
        std::fs::read(&whole).unwrap()
    );
    fails(
        &pm(&["run-job", s(&list), "--index", "3"]),
        "job index 3 is out of range",
    );
    fails(
        &pm(&["run-job", s(&list), "--merge", "--view", "p9"]),
        "no view `p9`",
    );

    // A site changed after the list was made: the job refuses to mix settings.
    let text = std::fs::read_to_string(&site).unwrap();
    std::fs::write(&site, text.replace("spp_max = 8", "spp_max = 12")).unwrap();
    fails(
        &pm(&["run-job", s(&list), "--index", "0"]),
        "changed after the job list",
    );
}

#[test]
fn bad_tiles_and_merges_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let site = tall_site(dir.path());
    let d = |name: &str| dir.path().join(name);
    let render = |tile: &str, out: &Path, extra: &[&str]| {
        let mut args = vec![
            "render",
            s(&site),
            "--view",
            "p1",
            "--tile",
            tile,
            "--out",
            s(out),
        ];
        args.extend(extra);
        pm(&args)
    };
    fails(&render("5/4", &d("x.exr"), &[]), "tile 5/4 is out of range");
    fails(&render("0/4", &d("x.exr"), &[]), "out of range");
    fails(&render("two/4", &d("x.exr"), &[]), "is not I/N");
    fails(&render("1/9", &d("x.exr"), &[]), "use at most 8");
    fails(&render("1/2", &d("x.png"), &[]), "name an .exr output");
    fails(
        &render("1/2", &dir.path().join("no/such/dir/x.exr"), &[]),
        "cannot write the output file",
    );
    assert!(!d("x.exr").exists(), "nothing written by refused tiles");

    for (i, seed) in [(1, "0"), (2, "0"), (2, "9")] {
        ok(&render(
            &format!("{i}/2"),
            &d(&format!("s{seed}-{i}.exr")),
            &["--seed", seed],
        ));
    }
    let merge = |parts: &[&str], out: &str| {
        let mut args = vec!["merge"];
        let paths: Vec<PathBuf> = parts.iter().map(|p| d(p)).collect();
        args.extend(paths.iter().map(|p| s(p)));
        let out = d(out);
        args.extend(["--out", s(&out)]);
        pm(&args)
    };
    fails(&merge(&["s0-1.exr"], "m.exr"), "missing tile 2 of 2");
    fails(
        &merge(&["s0-1.exr", "s0-1.exr", "s0-2.exr"], "m.exr"),
        "tile 1/2 is given twice",
    );
    fails(
        &merge(&["s0-1.exr", "s9-2.exr"], "m.exr"),
        "its seed is `9`",
    );
    ok(&pm(&[
        "render",
        s(&site),
        "--view",
        "p1",
        "--out",
        s(&d("plain.exr")),
    ]));
    fails(
        &merge(&["plain.exr"], "m.exr"),
        "is not a photomontage part",
    );
    assert!(!d("m.exr").exists(), "no partial merge written");
    ok(&merge(&["s0-2.exr", "s0-1.exr"], "m.png"));
}

#[test]
fn scheduler_files_are_written_for_slurm_kubernetes_and_flamenco() {
    let dir = tempfile::tempdir().unwrap();
    let site = tall_site(dir.path());
    let slurm = dir.path().join("slurm");
    ok(&pm(&[
        "slurm",
        s(&site),
        "--tiles",
        "4",
        "--throttle",
        "3",
        "--cpus-per-task",
        "2",
        "--exe",
        "/opt/pm/photomontage",
        "--out",
        s(&slurm),
    ]));
    let render = std::fs::read_to_string(slurm.join("render.sbatch")).unwrap();
    for needle in [
        "#SBATCH --array=0-3%3",
        "#SBATCH --cpus-per-task=2",
        "#SBATCH --requeue",
        "/opt/pm/photomontage run-job jobs.json --index \"$SLURM_ARRAY_TASK_ID\"",
        "scontrol requeue",
    ] {
        assert!(render.contains(needle), "`{needle}` not in:\n{render}");
    }
    let submit = std::fs::read_to_string(slurm.join("submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterok:"), "{submit}");
    assert!(
        std::fs::read_to_string(slurm.join("merge.sbatch"))
            .unwrap()
            .contains("--merge")
    );

    let k8s = dir.path().join("k8s");
    ok(&pm(&[
        "k8s",
        s(&site),
        "--tiles",
        "2",
        "--image",
        "example/pm:1",
        "--claim",
        "work",
        "--volume-root",
        s(dir.path()),
        "--out",
        s(&k8s),
    ]));
    let job = std::fs::read_to_string(k8s.join("render-job.yaml")).unwrap();
    for needle in [
        "completionMode: \"Indexed\"",
        "completions: 2",
        "\"/data/k8s/jobs.json\"",
    ] {
        assert!(job.contains(needle), "`{needle}` not in:\n{job}");
    }
    fails(
        &pm(&[
            "k8s",
            s(&site),
            "--image",
            "x",
            "--claim",
            "c",
            "--volume-root",
            s(&k8s),
            "--out",
            s(&dir.path().join("elsewhere")),
        ]),
        "is not under --volume-root",
    );

    let flamenco = dir.path().join("flamenco");
    ok(&pm(&[
        "flamenco",
        s(&site),
        "--tiles",
        "2",
        "--out",
        s(&flamenco),
    ]));
    let body: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(flamenco.join("flamenco-job.json")).unwrap())
            .unwrap();
    assert_eq!(body["settings"]["job_count"], 2);
    assert_eq!(body["type"], "photomontage-jobs");
    let script = std::fs::read_to_string(flamenco.join("photomontage_jobs.js")).unwrap();
    assert!(script.contains("function compileJob(job)"));

    fails(
        &pm(&[
            "jobs",
            s(&site),
            "--tiles",
            "0",
            "--out",
            s(&dir.path().join("j.json")),
        ]),
        "--tiles must be at least 1",
    );
    fails(
        &pm(&[
            "jobs",
            s(&site),
            "--views",
            "p9",
            "--out",
            s(&dir.path().join("j.json")),
        ]),
        "p9",
    );
    fails(
        &pm(&["slurm", s(&site), "--throttle", "0", "--out", s(&slurm)]),
        "--throttle must be at least 1",
    );
}

#[test]
fn a_part_folder_that_cannot_be_written_fails_before_the_render() {
    let dir = tempfile::tempdir().unwrap();
    let site = tall_site(dir.path());
    let list = dir.path().join("farm/jobs.json");
    ok(&pm(&["jobs", s(&site), "--tiles", "2", "--out", s(&list)]));
    // `parts` is a file, not a folder (permissions would not stop root): no part can go there.
    let parts = dir.path().join("farm/parts");
    std::fs::remove_dir(&parts).unwrap();
    std::fs::write(&parts, b"in the way").unwrap();
    let start = std::time::Instant::now();
    let o = pm(&["run-job", s(&list), "--index", "0"]);
    fails(&o, "cannot write in");
    assert!(!String::from_utf8_lossy(&o.stdout).contains("rendered"));
    fails(
        &pm(&["run-job", s(&list), "--merge"]),
        "missing tiles 1, 2 of 2",
    );
    eprintln!("refused in {:.2} s", start.elapsed().as_secs_f64());
}

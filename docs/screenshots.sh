#!/usr/bin/env bash
# Retakes the studio screenshots of docs/user-guide.md in a real window (eframe on Mesa's
# llvmpipe) under xvfb-run, with the studio's own --screenshot mode (it waits until the workers
# are idle, so a study has finished before the picture is taken).
#
#   bash docs/screenshots.sh [--release] [TAB ...]
#
# Without TAB arguments it takes the Study tab shots (docs/images/studio-study-shadow.png, which
# the user guide shows, and studio-study.png with montages, which takes long in a debug build and
# is not in the guide yet) and one shot of each further side tab it knows by label
# ("Site & light", "Materials", "Variants": docs/images/studio-<tab>.png; "Elevation": the Materials
# tab with its unfolded elevation drawn by irradiance; "Radiosity": the Site & light tab scrolled
# to its exposure and radiosity switches; "Study": the shadow-map shot alone); a tab
# the studio does not know yet (`--tab` refuses it) is skipped with a note. With TAB arguments only those tabs.
# A new tab needs its label in `Studio::select_tab` (app/src/study_panel.rs).
#
# The site is a temporary copy of sample_sites/street with `location.time_zone =
# "Europe/Zurich"` and the rays per pixel lowered to 4–8 (so that the debug build takes
# minutes, not hours), solved with `photomontage solve`. Needs xvfb-run (package xvfb) and the
# Mesa GL drivers.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
profile=debug
build_flag=()
if [[ ${1:-} == --release ]]; then
    profile=release
    build_flag=(--release)
    shift
fi
tabs=("$@")

if [[ -z ${SCREENSHOTS_NO_BUILD:-} ]]; then  # set it to use the binaries already built
    cargo build --locked "${build_flag[@]}" -p photomontage --bin photomontage
    cargo build --locked "${build_flag[@]}" -p photomontage-studio --bin photomontage-studio
fi
bin="$root/target/$profile"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r sample_sites/street "$work/street"
site="$work/street/site.toml"
python3 - "$site" <<'PY'
import sys
path = sys.argv[1]
text = open(path).read()
text = text.replace('grid_convergence_deg = 0.0\n',
                    'grid_convergence_deg = 0.0\ntime_zone = "Europe/Zurich"\n', 1)
text = text.replace('\n[[photos]]', '\n[render]\nspp_min = 4\nspp_max = 8\n\n[[photos]]', 1)
# Two design variants for the Variants tab: the planned building as drawn, and recoloured.
text += '''
[[variants]]
name = "As planned"
visible_models = ["planned"]

[[variants]]
name = "Terracotta"
visible_models = ["planned"]

[[variants.materials]]
name = "cladding"
diffuse_rgb = [0.52, 0.16, 0.08]
'''
open(path, 'w').write(text)
PY
"$bin/photomontage" solve "$site" >/dev/null

shot() {
    local out=$1
    shift
    xvfb-run -a -s "-screen 0 1920x1200x24" \
        "$bin/photomontage-studio" "${shot_site:-$site}" --frames 30 --screenshot "$out" "$@" || return 1
    echo "wrote $out"
}

if [[ ${#tabs[@]} -eq 0 ]]; then
    shot docs/images/studio-study.png --tab Study \
        --study-dates 2026-06-21 --study-times 09:00,12:00,15:00 --study-frame 1
    shot docs/images/studio-study-shadow.png --tab Study --study-dates 2026-03-20,2026-06-21 \
        --study-times 09:00,12:00,17:00 --study-shadow-maps --study-no-montages --study-frame 4
    tabs=("Site & light" "Materials" "Variants" "Elevation" "Radiosity")
fi
for tab in "${tabs[@]}"; do
    slug=$(echo "$tab" | tr '[:upper:]' '[:lower:]' | sed 's/[^a-z0-9]\+/-/g; s/-$//')
    extra=()
    if [[ $tab == Variants ]]; then
        extra=(--render-variants)  # both variants rendered, shown on the A/B slider
    fi
    if [[ $tab == Study ]]; then
        # The shadow-map study alone (quick); the montage study only without TAB arguments.
        shot docs/images/studio-study-shadow.png --tab Study --study-dates 2026-03-20,2026-06-21 \
            --study-times 09:00,12:00,17:00 --study-shadow-maps --study-no-montages --study-frame 4
        continue
    fi
    shot_site=$site
    if [[ $tab == Radiosity ]]; then
        # The Site & light tab scrolled to the exposure and the radiosity switches, on a copy of
        # the solved site with the radiosity mode on.
        tab="Site & light"
        extra=(--light-render-settings)
        shot_site="$work/street/site-radiosity.toml"
        sed 's/^spp_max = 8$/spp_max = 8\nradiosity = true/' "$site" > "$shot_site"
    fi
    if [[ $tab == Elevation ]]; then
        # The Materials tab's unfolded elevation of the planned building, by irradiance.
        tab=Materials
        extra=(--elevation --elevation-irradiance)
    fi
    if "$bin/photomontage-studio" --help >/dev/null && shot "docs/images/studio-$slug.png" --tab "$tab" "${extra[@]}"; then
        :
    else
        echo "note: no screenshot of tab \"$tab\" (the studio does not know it)" >&2
    fi
done

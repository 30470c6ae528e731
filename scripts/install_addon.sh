#!/usr/bin/env bash
# Installs the AO Lab add-on into Blender and enables it (docs/blender_addon.md), the way the
# Blender it finds expects:
#   Blender 4.2+   as an extension: `blender --command extension build` makes the package from
#                  blender_addon/aolab_blender (its blender_manifest.toml), and
#                  `blender --command extension install-file -r user_default --enable` installs
#                  it into the user repository (module bl_ext.user_default.aolab_blender);
#   Blender 3.4    as a legacy add-on: a zip of the package's .py files, its export/
#                  subpackage's too (bl_info), installed
#                  with the preferences' add-on operators (module aolab_blender).
#
#   scripts/install_addon.sh             make the package, install it, enable it, save the
#                                        preferences
#   scripts/install_addon.sh --zip-only  only make the package (then, in Blender: Edit >
#                                        Preferences > Add-ons (4.2+: Get Extensions >
#                                        Install from Disk...), pick it, tick "AO Lab")
#
# The package goes to dist/ (AOLAB_ADDON_ZIP overrides). Blender's user folders are its
# defaults (~/.config/blender/X.Y) unless BLENDER_USER_CONFIG / BLENDER_USER_SCRIPTS (and on
# 4.2+ BLENDER_USER_EXTENSIONS) say otherwise: the tests install into temporary ones. The
# `aolab` package it imports is found through the .pth that scripts/setup.sh writes.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
src="$root/blender_addon/aolab_blender"
blender="${AOLAB_BLENDER:-blender}"
version="$("$blender" -b --factory-startup -noaudio --version 2>/dev/null | sed -n 's/^Blender \([0-9][0-9]*\.[0-9][0-9]*\).*/\1/p' | head -n 1)"
[ -n "$version" ] || { echo "install_addon: cannot run '$blender --version'" >&2; exit 2; }
major="${version%%.*}"
minor="${version#*.}"
extension=0
if [ "$major" -gt 4 ] || { [ "$major" -eq 4 ] && [ "$minor" -ge 2 ]; }; then extension=1; fi
zip="${AOLAB_ADDON_ZIP:-$root/dist/aolab_blender$([ $extension = 1 ] && echo -extension).zip}"
mkdir -p "$(dirname "$zip")"

if [ $extension = 1 ]; then
  # Built from a copy without __pycache__ (a checkout that ran its tests has them).
  stage="$(mktemp -d)"
  trap 'rm -rf "$stage"' EXIT
  cp -r "$src"/. "$stage/"
  find "$stage" -name __pycache__ -prune -exec rm -rf {} +
  "$blender" -b --factory-startup -noaudio --command extension build --source-dir "$stage" \
    --output-filepath "$zip.tmp.zip" | { grep -v '^Blender [0-9]' || true; }
  # `extension build` reports an invalid manifest as FATAL_ERROR but exits with status 0
  [ -s "$zip.tmp.zip" ] || { echo "install_addon: no extension package built (see above)" >&2; exit 1; }
  mv "$zip.tmp.zip" "$zip"
else
  /usr/bin/python3 - "$src" "$zip" <<'PY'
import os, sys, zipfile
src, out = sys.argv[1:]
tmp = out + ".tmp"
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
    for folder, dirs, names in os.walk(src):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(n for n in names if n.endswith(".py")):
            path = os.path.join(folder, name)
            z.write(path, os.path.join("aolab_blender", os.path.relpath(path, src)))
os.replace(tmp, out)
PY
fi
echo "install_addon: wrote $zip (Blender $version: $([ $extension = 1 ] && echo extension || echo legacy add-on))"
[ "${1:-}" = "--zip-only" ] && exit 0

if [ $extension = 1 ]; then
  "$blender" -b --factory-startup -noaudio --command extension install-file -r user_default \
    --enable "$zip"
  module=bl_ext.user_default.aolab_blender
else
  AOLAB_ADDON_ZIP="$zip" "$blender" -b -noaudio --python-exit-code 1 --python-expr '
import os, bpy
bpy.ops.preferences.addon_install(filepath=os.environ["AOLAB_ADDON_ZIP"], overwrite=True)
bpy.ops.preferences.addon_enable(module="aolab_blender")
bpy.ops.wm.save_userpref()
'
  module=aolab_blender
fi
# Whichever way it went in, a new Blender must now start with the add-on enabled.
AOLAB_ADDON_MODULE="$module" "$blender" -b -noaudio --python-exit-code 1 --python-expr '
import os, addon_utils, bpy
module = os.environ["AOLAB_ADDON_MODULE"]
if not addon_utils.check(module)[1]:
    raise SystemExit(f"install_addon: the add-on {module} did not enable (see the messages above)")
print(f"install_addon: AO Lab enabled as {module}")
'

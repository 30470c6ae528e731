#!/usr/bin/env bash
# Installs the AO Lab add-on into Blender and enables it (docs/blender_addon.md).
#
#   scripts/install_addon.sh             zip blender_addon/aolab_blender as
#                                        dist/aolab_blender.zip, install it, enable it, save
#                                        the preferences
#   scripts/install_addon.sh --zip-only  only make the zip (then: Edit > Preferences > Add-ons >
#                                        Install..., pick dist/aolab_blender.zip, tick "AO Lab")
#
# The add-on's module is `aolab_blender`, as in the checkout. Blender's user folders are its
# defaults (~/.config/blender/3.4) unless BLENDER_USER_CONFIG / BLENDER_USER_SCRIPTS say
# otherwise (the tests install into temporary ones). The `aolab` package it imports is found
# through the .pth that scripts/setup.sh writes.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
blender="${AOLAB_BLENDER:-blender}"
zip="${AOLAB_ADDON_ZIP:-$root/dist/aolab_blender.zip}"
mkdir -p "$(dirname "$zip")"

/usr/bin/python3 - "$root/blender_addon/aolab_blender" "$zip" <<'PY'
import os, sys, zipfile
src, out = sys.argv[1:]
tmp = out + ".tmp"
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
    for name in sorted(os.listdir(src)):
        if name.endswith(".py"):
            z.write(os.path.join(src, name), f"aolab_blender/{name}")
os.replace(tmp, out)
PY
echo "install_addon: wrote $zip"
[ "${1:-}" = "--zip-only" ] && exit 0

AOLAB_ADDON_ZIP="$zip" "$blender" -b -noaudio --python-exit-code 1 --python-expr '
import os, addon_utils, bpy
bpy.ops.preferences.addon_install(filepath=os.environ["AOLAB_ADDON_ZIP"], overwrite=True)
bpy.ops.preferences.addon_enable(module="aolab_blender")
loaded_default, loaded = addon_utils.check("aolab_blender")
if not loaded:
    raise SystemExit("install_addon: the add-on did not enable (see the messages above)")
bpy.ops.wm.save_userpref()
print("install_addon: AO Lab enabled from", bpy.utils.user_resource("SCRIPTS", path="addons"))
'

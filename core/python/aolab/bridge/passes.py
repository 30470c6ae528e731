"""Which render passes a reference needs (no bpy): only what the chosen methods and the
scene's effects (its manifest's "effects") require (docs/conventions.md, "Effects and the
passes they need")."""

from __future__ import annotations

# Our pass name -> (view-layer property that enables it, Blender pass name in the EXR,
# channels).
PASSES = {
    "depth": ("use_pass_z", "Depth", ("Z",)),
    "normal": ("use_pass_normal", "Normal", ("X", "Y", "Z")),
    "diffuse_color": ("use_pass_diffuse_color", "DiffCol", ("R", "G", "B")),
    "emission": ("use_pass_emit", "Emit", ("R", "G", "B")),
    # Cycles' Vector pass; the EXR gets it converted to AO Lab's convention as Motion.X/Y
    # (bridge/motion.py).
    "motion": ("use_pass_vector", "Vector", ("X", "Y", "Z", "W")),
}
#: Passes that are files beside the EXR, not render passes: no view-layer pass is enabled
#: for them, and no method needs them (required_passes never adds them). "mesh": the scene's
#: world-space triangles, <stem>.mesh + <stem>.mesh.json (bridge/mesh.py).
GEOMETRY_PASSES = ("mesh",)
EFFECTS = ("color_bleeding", "luminance_sensitivity")


def required_passes(methods: list[dict], effects: list[str], *,
                    sequence: bool = False) -> list[str]:
    """The G-buffer passes for `methods` (dicts with needs_normal / needs_color, as
    aolab.method_info returns) on a scene whose manifest asks for `effects`.

    Depth always; Normal if a method reads normals; the diffuse colour for colour bleeding
    and emission plus diffuse colour for luminance sensitivity, but only if a method reads
    colour at all; the motion vectors for a `sequence` (a manifest with "frames"), which
    temporal accumulation reprojects its history with.
    """
    unknown = [e for e in effects if e not in EFFECTS]
    if unknown:
        raise ValueError(f"effects must be among {', '.join(EFFECTS)}, got {unknown}")
    passes = ["depth"]
    if any(m.get("needs_normal") for m in methods):
        passes.append("normal")
    if any(m.get("needs_color") for m in methods):
        if "color_bleeding" in effects or "luminance_sensitivity" in effects:
            passes.append("diffuse_color")
        if "luminance_sensitivity" in effects:
            passes.append("emission")
    if sequence:
        passes.append("motion")
    return passes


def parse_passes(text: str) -> list[str]:
    """'depth,normal' -> ['depth', 'normal'], checked; depth is always included."""
    names = [p.strip() for p in text.split(",") if p.strip()]
    known = list(PASSES) + list(GEOMETRY_PASSES)
    bad = [p for p in names if p not in known]
    if bad:
        raise ValueError(f"passes must be among {', '.join(known)}, got {bad}")
    return ["depth"] + [p for p in known if p in names and p != "depth"]

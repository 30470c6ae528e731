"""What differs between the Blender releases AO Lab supports (3.4 to 4.x), in one place (bpy).

Everything else in the add-on and the bridge is written once for all of them. The differences
were measured on Blender 3.4.1 (Debian 12) and 4.3.2 (Debian 13); docs/blender_facts.md lists
them with the tests that re-verify each:

- EEVEE. Blender 4.2 replaced EEVEE (engine BLENDER_EEVEE, GTAO with `use_gtao`,
  `gtao_factor`, `use_gtao_bounce`, `use_gtao_bent_normals`, bloom and SSR switches) by EEVEE
  Next (engine BLENDER_EEVEE_NEXT in 4.2 to 4.4): its AO render pass is a horizon scan whose
  distance is still `gtao_distance`, with the fast-GI thickness and bias settings; the old
  switches are gone. `eevee_ao_settings` gives each its own settings mapped to R.
- Renamed properties: ParticleSettings `child_nbr` (3.4) is `child_percent` (4.0+).
- The add-on's packaging: 4.2+ installs it as an extension (blender_manifest.toml), under the
  module name `bl_ext.<repository>.aolab_blender`; 3.4 as a legacy add-on (`bl_info`) under
  `aolab_blender`. The code only ever uses `__package__`, so both names work.
"""

from __future__ import annotations

import bpy

#: The viewport's count of child particles per parent: `child_nbr` until Blender 4.0 renamed
#: it `child_percent` (the render count, `rendered_child_count`, kept its name).
PARTICLE_VIEWPORT_CHILDREN = ("child_percent" if "child_percent" in
                              bpy.types.ParticleSettings.bl_rna.properties.keys() else "child_nbr")

#: TAA samples of the EEVEE renders: GTAO (3.4) converges in a few; EEVEE Next's horizon scan
#: is noisier per sample, and 16 keeps its residual noise below the reference's (measured,
#: docs/blender_facts.md).
EEVEE_SAMPLES = 16


def is_eevee_next() -> bool:
    """True where EEVEE is EEVEE Next (Blender 4.2+): no GTAO switches, a horizon-scan AO pass."""
    return "use_gtao_bounce" not in bpy.types.SceneEEVEE.bl_rna.properties.keys()


def eevee_engine() -> str:
    """The render engine identifier of EEVEE in this Blender (BLENDER_EEVEE_NEXT in 4.2 to
    4.4, BLENDER_EEVEE before and after)."""
    items = bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items.keys()
    return "BLENDER_EEVEE_NEXT" if "BLENDER_EEVEE_NEXT" in items else "BLENDER_EEVEE"


def eevee_peer_name() -> str:
    """The name the study knows this Blender's EEVEE peer by."""
    return "eevee_next" if is_eevee_next() else "eevee_gtao"


def eevee_ao_settings(eevee, radius: float) -> dict:
    """The `scene.eevee` settings of an AO-pass render at distance `radius`, as attribute ->
    value. Settings the user owns and that have no counterpart in the reference's definition
    (GTAO's precision and bent normals; EEVEE Next's thickness, bias and precision) keep the
    scene's values and are recorded as they were, so that peers.json says what was rendered."""
    chosen = {"gtao_distance": radius, "taa_render_samples": EEVEE_SAMPLES}
    if is_eevee_next():
        # The AO pass is computed whether or not use_gtao (kept in RNA, unused) is on; the
        # horizon scan reads the fast-GI thickness and bias and gtao_quality (precision).
        for attr in ("gtao_quality", "fast_gi_thickness_near", "fast_gi_thickness_far",
                     "fast_gi_bias"):
            chosen[attr] = getattr(eevee, attr)
        return chosen
    # GTAO: factor 1, the bounce approximation off (it brightens AO, which the Cycles pass
    # does not); bloom, SSR and motion blur off so that nothing else reaches the pass.
    chosen.update(use_gtao=True, gtao_factor=1.0, use_gtao_bounce=False,
                  gtao_quality=eevee.gtao_quality,
                  use_gtao_bent_normals=eevee.use_gtao_bent_normals,
                  use_bloom=False, use_ssr=False, use_motion_blur=False)
    return chosen


#: 3.4's EEVEE writes the half float maximum where nothing is drawn.
GTAO_BACKGROUND_DEPTH = 65504.0


def eevee_background_depth(camera) -> float:
    """The depth at or beyond which a pixel of an EEVEE render is background, for the camera
    data `camera`. 3.4's EEVEE writes 65504 there (so: 99 % of it). EEVEE Next writes the far
    plane, reconstructed from its depth buffer, whose resolution there is about
    clip_end² / clip_start · 2^-24: measured 1000.07 for a clip end of 1000, and below 200 for
    one of 200 (the committed scenes). So 8 times that resolution below the clip end; no
    surface of the committed scenes lies so near it."""
    if not is_eevee_next():
        return GTAO_BACKGROUND_DEPTH * 0.99
    margin = max(1e-4, 8.0 * camera.clip_end / camera.clip_start * 2.0 ** -24)
    return camera.clip_end * (1.0 - margin)

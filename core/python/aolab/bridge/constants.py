"""What the bpy side (blender_addon/aolab_blender) and the aolab side agree on: output file
names, the bridge version in the cache key and the sidecar, the background rule, and the
comparison peers' Cycles ladder."""

#: Bump when the bridge's output changes: invalidates cached results.
BRIDGE_VERSION = 1
RESULT_EXR = "reference.exr"
RESULT_JSON = "reference.json"
RESULT_MESH = "reference.mesh"            # the `mesh` pass: scene triangles (bridge/mesh.py)
RESULT_MESH_JSON = "reference.mesh.json"
PEERS_DIR = "peers"          # reference_scenes/<scene>/peers/
PEERS_JSON = "peers.json"
#: EEVEE Next's render (Blender 4.2+) beside the 3.4 peers: the peers.json of an
#: `aolab reference --peers --ladder none` run on Blender 4.x, renamed
#: (scripts/update_references.sh --eevee-next).
EEVEE_NEXT_JSON = "eevee_next.json"
#: Cycles writes 1e10 where nothing is hit: depth at or beyond this is background.
BACKGROUND_DEPTH = 1e9
#: The Cycles ladder of the comparison peers: samples per rung (seed LADDER_SEED).
LADDER_SPP = (1, 4, 16, 64, 256)
LADDER_SEED = 1              # the reference uses seed 0: independent samples

"""Corpus scene `terrain_wide`: variant 0 of reference_scenes/families/terrain.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.terrain").terrain.build(0)

"""Corpus scene `clutter_shelf`: variant 2 of reference_scenes/families/clutter.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.clutter").clutter.build(2)

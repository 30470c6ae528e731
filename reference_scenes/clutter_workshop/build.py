"""Corpus scene `clutter_workshop`: variant 1 of reference_scenes/families/clutter.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.clutter").clutter.build(1)

"""Sequence `sequence_pan`: variant "pan" of reference_scenes/families/sequences.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.sequences").sequences.build("pan")

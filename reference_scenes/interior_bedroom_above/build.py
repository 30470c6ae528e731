"""Corpus scene `interior_bedroom_above`: variant 1 of reference_scenes/families/interior.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.interior").interior.build(1)

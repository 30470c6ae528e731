"""Corpus scene `thin_balustrade`: variant 2 of reference_scenes/families/thin.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.thin").thin.build(2)

"""Corpus scene `mechanical_bracket`: variant 2 of reference_scenes/families/mechanical.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.mechanical").mechanical.build(2)

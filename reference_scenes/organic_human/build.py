"""Corpus scene `organic_human`: variant 1 of reference_scenes/families/organic.py."""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # reference_scenes/
__import__("families.organic").organic.build(1)

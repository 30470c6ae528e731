"""scripts/sample_counts.py finds its phases in the HBAO sources: a kernel edited so that a
marker line is gone or moved out of order fails here, not after a 10-minute coverage build."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
SPEC = importlib.util.spec_from_file_location("sample_counts", ROOT / "scripts/sample_counts.py")
sample_counts = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(sample_counts)


@pytest.mark.parametrize("kernel", sorted(sample_counts.FUNNELS))
def test_every_phase_has_its_line_in_order(kernel):
    source, anchor, phases = sample_counts.FUNNELS[kernel]
    numbers = sample_counts.line_numbers(ROOT / "core/methods/hbao" / source, anchor, phases)
    assert list(numbers) == list(phases)
    if kernel == "simd":   # one function, its phases in the order they run
        assert list(numbers.values()) == sorted(numbers.values())


def test_a_missing_line_is_named(tmp_path):
    source = tmp_path / "k.cpp"
    source.write_text("void f() {\n  int a = 0;\n}\n")
    with pytest.raises(SystemExit, match="no line 'int b = 0;'"):
        sample_counts.line_numbers(source, "void f(", {"given": ("int b = 0;", 1)})

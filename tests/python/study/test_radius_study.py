"""aolab radius-study: the configurations it compares and the table it writes (the study
itself renders references for half an hour: `aolab radius-study`, docs/benchmarks.md)."""
import pytest

import aolab
from aolab import cli
from aolab.study import radius_study as rs


def test_pyramid_levels_follow_pyramid_hbaos_rule():
    # S·(K^L − 1)/(K − 1) ≥ R·f/d: with S = 4, K = 3 the reach is 4, 16, 52, 160 px
    assert [rs.pyramid_levels(px, 4, 3) for px in (1, 4, 4.5, 16, 17, 52, 53, 160)] == \
        [1, 1, 2, 2, 3, 3, 4, 4]


def test_sao_gets_pyramid_hbaos_samples_per_pixel_up_to_its_most():
    most = int(rs.max_of("sao", "samples"))
    for scale, px in ((1.0, 30.0), (2.0, 60.0), (4.0, 200.0)):
        hbao, hbao_cycles, pyramid, pyramid_cycles, sao = rs.configurations(scale, px)
        assert hbao["settings"] == {"directions": 8, "steps": round(8 * scale)}
        assert hbao_cycles["settings"] == {**hbao["settings"], "attenuation": "none",
                                           "integral": "cosine"}
        assert pyramid_cycles["settings"] == {"attenuation": "none"}
        assert sao["samples"] == min(most, pyramid["samples"])
        assert ("its most" in sao["note"]) == (pyramid["samples"] > most)
        for c in (hbao, hbao_cycles, pyramid, pyramid_cycles, sao):   # settings that exist
            names = {s["name"] for s in aolab.method_info(c["method"])["settings"]}
            assert set(c["settings"]) | (set(c["timed"]) - {"blur"}) <= names


def test_table_has_a_row_per_scene_scale_and_configuration():
    rows = [{"scene": s, "scale": k, "radius": 0.5 * k, "radius_px": 40 * k, "method": m,
             "label": rs.LABELS[m], "config": "c", "samples": 64, "median_ms": 12.5,
             "mae": 0.05, "occluded_mae": 0.1, "ssim": 0.9}
            for s in ("street", "room") for k in (1.0, 0.5) for m in rs.METHODS]
    lines = rs.table(rows).strip().splitlines()
    assert len(lines) == 2 + 12
    assert lines[2] == "| room | 0.25 (×0.5) | 20 px | HBAO (c) | 64 | 12.5 | 0.0500 | " \
        "0.1000 | 0.900 |"
    assert lines[-1].startswith("| street | 0.5 (×1) | 40 px | Scalable AO (c) |")


def test_bad_scales_are_refused_when_read(capsys):
    for bad in ("0", "-1", "nan", "65"):
        with pytest.raises(SystemExit):
            cli.build_parser().parse_args(["radius-study", "--scales", bad])
        assert "--scales" in capsys.readouterr().err

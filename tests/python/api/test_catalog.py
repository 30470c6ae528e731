"""aolab.catalog: one module per method, the bottom layer of what the study knows of it (its
presets and sweep, tuning bounds and fixed settings, samples per pixel)."""
import ast
import types
from pathlib import Path

import aolab
from aolab import catalog, named_presets
from aolab.catalog.kinds import PRESET_ORDER, SHARED_BOUNDS, Param

CATALOG = Path(catalog.__file__).parent


def test_every_module_of_the_folder_is_an_entry_of_a_method():
    modules = {p.stem for p in CATALOG.glob("*.py")} - {"__init__", "kinds"}
    names = {m.__name__.rsplit(".", 1)[1] for m in catalog.MODULES}
    assert names == modules == set(catalog.ENTRIES)
    assert set(catalog.ENTRIES) <= set(aolab.methods())
    assert catalog.entry("screen_space_limit") is None


def test_the_catalog_imports_nothing_of_aolab_but_itself():
    """Relative imports of the catalog's own modules only: not aolab, _core or the modules
    that read the catalog (named_presets, tune), so that any of them may import it."""
    for path in sorted(CATALOG.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and node.level > 0:
                assert node.level == 1 and node.module in (None, "kinds"), \
                    f"{path.name}:{node.lineno}"
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) \
                    else [node.module]
                assert not any(n.split(".")[0] == "aolab" for n in names), \
                    f"{path.name}:{node.lineno}"


def test_every_entry_names_settings_of_its_method():
    """A mistyped name would be dropped silently (a bound never applied, a setting searched
    that should be fixed): every name an entry gives is a setting of the method."""
    for method, e in catalog.ENTRIES.items():
        settings = {s["name"]: s for s in aolab.method_info(method)["settings"]}
        for name, values in e.presets.items():
            assert name in PRESET_ORDER
            assert set(values) <= set(settings) | {"blur"}, (method, name)
        assert set(e.sweep) <= set(settings) | {"blur"}, method
        assert set(e.tune_bounds) <= set(settings), method
        assert set(e.tune_fixed) <= set(settings), method
        assert all(isinstance(b, Param) and b.why for b in e.tune_bounds.values()), method
        if e.builtin_blur is not None:
            assert settings[e.builtin_blur]["type"] == "bool", method
        if e.samples_per_pixel is not None:
            defaults = {name: s["default"] for name, s in settings.items()}
            assert e.samples_per_pixel(defaults) > 0, method
    for method in aolab.methods():
        assert set(SHARED_BOUNDS) <= {s["name"] for s in aolab.method_info(method)["settings"]}


def test_presets_is_a_function_and_named_presets_a_plain_module():
    assert isinstance(aolab.presets, types.FunctionType)
    assert not callable(named_presets)     # the module no longer answers the call
    assert aolab.presets("hbao") == named_presets.named("hbao")

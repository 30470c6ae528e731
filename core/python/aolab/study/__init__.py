"""The comparison study: ``compare`` (every method against the reference on every scene,
timed and scored over ``runner``, the one way a configuration is run, timed and scored;
its rows in ``results``, its folder in ``output``), ``findings`` (what its results say, as
data), ``charts`` (their plots), two views of the same findings: ``report`` (report.html, its
tables in ``report_tables``) with ``report_files`` (its folder of images and scripts, and
report.js) and ``results_doc`` (docs/results.md and its per-scene and per-sequence pages),
``tune`` (the tuned presets), ``budget`` (the choice within a time budget that report and tune
share), ``limits`` (the screen-space limit of each scene) and ``radius_study``.

What the study knows of each method (presets, sweep grid, tune bounds, samples per pixel) is
in ``aolab.catalog``, one module per method, below the API.
"""

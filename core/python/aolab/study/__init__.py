"""The comparison study: ``compare`` (every method against the reference on every scene,
timed and scored), ``report`` (report.html) with ``report_files`` (its folder of images and
scripts, and report.js), ``results_doc`` (docs/results.md), ``tune``
(the tuned presets), ``budget`` (the choice within a time budget that report and tune
share), ``limits`` (the screen-space limit of each scene) and ``radius_study``.

What the study knows of each method (presets, sweep grid, tune bounds, samples per pixel) is
in ``aolab.catalog``, one module per method, below the API.
"""

"""``clutchlab demo``: one section of the demo report per model, on the bundled synthetic data.

Each module has ``demo_section(progress)`` returning a :class:`clutchlab.report.Section`; the command
(:mod:`clutchlab.cli`) runs them in the order of :data:`clutchlab.cli.DEMO_SECTIONS` and writes the report.
The demos stand above the models, the driveline, control and the report they show (docs/architecture.md,
"Layers").
"""

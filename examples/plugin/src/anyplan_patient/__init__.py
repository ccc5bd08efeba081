"""An example anyplan plugin (see ``examples/plugin/README.md``)."""

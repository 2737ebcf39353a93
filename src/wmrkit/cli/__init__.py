"""The ``wmrkit`` command: thin parsers over library calls, one module per command group."""

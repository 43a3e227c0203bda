"""The ``facetraj`` command: one console command above both packages.

``engine`` (the synthesis engine) and ``app`` (the desktop app and its headless renderers) never
import this package; it imports both. Each subcommand lives in a module of
:mod:`facetraj.commands`, registered in :data:`facetraj.cli.COMMANDS`.
"""

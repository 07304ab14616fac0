"""The command line (`gridshell`): `main(argv=None)` in :mod:`.main`, one module per subcommand
with `add_args(parser)` and `run(args)`; :mod:`.outcome` keeps the ``--json`` / ``-q`` contract of
every command.

May import: everything; nothing imports it but ``gridshell.__main__`` and the entry point.
"""

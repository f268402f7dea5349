"""The command line: the entry point (`console`), the argument parser and
commands (`parser`), and one validated run, to and from TOML (`scenario`)."""

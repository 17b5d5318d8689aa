"""``python -m lookalike``: the command line without an installed entry point."""

from lookalike.cli import main

if __name__ == "__main__":
    main()

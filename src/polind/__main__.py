"""``python -m polind``: the same command line as the ``polind`` script."""

from polind.cli import main

if __name__ == "__main__":
    main()

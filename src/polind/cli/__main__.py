"""``python -m polind.cli``: the same command line as the ``polind`` script (as before the package)."""

from polind.cli import main

if __name__ == "__main__":
    main()

import sys

from .batch import main

# Guarded: Dask's worker processes (multiprocessing spawn) import the parent's __main__
# module under another name, and must not run the command line again.
if __name__ == "__main__":
    sys.exit(main())

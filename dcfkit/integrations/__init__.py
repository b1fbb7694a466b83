"""Glue to the community's tracking toolkits, one module per toolkit.

Each module imports its toolkit when it is imported, so ``import dcfkit`` never needs
them: install the extra that names the toolkit (``pip install "dcfkit[got10k]"``).
"""

"""transport layer (see servostudio/__init__.py)."""

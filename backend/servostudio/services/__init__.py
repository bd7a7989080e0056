"""services layer (see servostudio/__init__.py)."""

"""api/routes layer (see servostudio/__init__.py)."""

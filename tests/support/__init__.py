"""Helpers and fixtures shared by several test folders (the root conftest registers the fixture modules)."""

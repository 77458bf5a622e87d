"""Geometry: parametric primitives sized from their cells, and the façade scene."""

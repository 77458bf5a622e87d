"""Buildings and cities: footprints, manifests, whole buildings, city runs (SPEC 5)."""

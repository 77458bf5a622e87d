"""From a labelled façade back to a layered spec (``facade infer``)."""

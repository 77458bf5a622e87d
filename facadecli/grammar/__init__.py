"""From a labelled façade back to rules (Wu et al. 2014): layout input and tiling so far."""

"""vrflow from Python (minimal stand-in by helper "pyapp"; pymod's replaces it)."""

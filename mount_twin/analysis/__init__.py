"""Analyses of scenes and results: adapters on the core; the core never imports them."""

"""Analyses of scenes and results, on the layers below (the core, the model, the engine, io);
the adapters (node, replay, commands) use them, and no analysis imports an adapter
(docs/design.md, test/test_layers.py)."""

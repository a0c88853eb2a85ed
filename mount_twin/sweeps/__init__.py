"""Design sweeps: many scene variants × many inputs, run on a Dask cluster (an adapter: it uses
the core, the core never imports it)."""

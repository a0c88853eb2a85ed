"""Design sweeps: many scene variants × many inputs, run on a Dask cluster (in the analysis
layer, docs/design.md: it uses the layers below, and only the command line and
the package's names (`mount_twin.__init__`) import it)."""

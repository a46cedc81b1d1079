"""Help texts of the Dask options that ``poro2d sweep`` and ``poro2d relation`` share."""

SCHEDULER_HELP = "Address of a running Dask scheduler (e.g. tcp://host:8786); default: a LocalCluster."
WORKERS_HELP = "Worker processes of the LocalCluster (default: one per core, one thread each)."
DASHBOARD_HELP = "LocalCluster dashboard: HOST:PORT or none (default 127.0.0.1:0, this machine only)."

"""The co-simulation engine: documents and their schemas, the system (wiring) and scenario models,
the FMI instances, the master algorithm, the runner and its result files and plots.

Reading order: `documents` (strict JSON + schema) -> `system` (components, connections, checks)
and `ordering` (Gauss-Seidel sweep) -> `scenario` -> `fmi_instance` -> `master` -> `runner`
(`results`, `plots`). `errors` holds the error types every layer raises.
"""

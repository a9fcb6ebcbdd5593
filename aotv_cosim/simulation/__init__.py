"""Running a loaded scenario: FMU instances behind one contract (`instance.FmuInstance`), called
through FMI's C functions (`fmi2_instance`, `fmi3_instance` on `c_instance`) or, for this
package's FMUs, directly in this interpreter (`direct_instance`); the order of steps and value
exchange (`ordering`); the coupling that owns the value buffer and makes one communication step
(`coupling`); the master's fixed-step loop (`master`) and error-controlled loop (`step_doubling`);
recorded rows (`rows`); the step watchdog and deferred signals (`watchdog`, `interrupts`); the
extracted FMU files (`unpacked`); and loading with FMUs built on first use (`loading`).

Reading order: `master` -> `coupling` -> `instance` -> `c_instance` / `direct_instance` -> `step_doubling`.
"""

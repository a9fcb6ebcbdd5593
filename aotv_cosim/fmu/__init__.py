"""The FMU side: the pythonfmu adapter bases every class of ``fmus_src`` derives from (`slave`,
`vehicle_slave`, `guidance_slave`, `bank_guidance`, `actuator_slave`) and the build (`build`).

Every module here but `build` is bundled into each FMU (``build.RUNTIME``) and may import only
numpy, scipy, pythonfmu, the standard library and the other bundled modules; this file must stay
import-free.
"""

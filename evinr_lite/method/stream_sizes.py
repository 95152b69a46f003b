"""How much a streamed reconstruction predicts and tone-maps at once: shared by the stream
(:mod:`~evinr_lite.method.streaming`), which uses them, and the memory estimate
(:mod:`~evinr_lite.method.memory`), which counts them, so neither imports the other for them."""

__all__ = ["PREDICT_CELLS", "MIN_BATCH", "TONEMAP_CELLS"]

PREDICT_CELLS = 1 << 23     # frames x pixels per prediction batch (32 MB of float32) ...
MIN_BATCH = 32              # ... but at least this many frames: each batch reads the d x H*W head once
TONEMAP_CELLS = 1 << 21     # frames x pixels tone-mapped at once (its float64 work arrays stay ~50 MB)

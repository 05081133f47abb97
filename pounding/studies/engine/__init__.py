"""The study engine: every study (sweep, compare, gap, IDA) runs its scenarios through it.

``tasks``      scenarios and task sources: a static list, or an adaptive source (IDA hunt-and-fill)
``keys``       what a stored result depends on (model document, record content, pounding's code), hashed
``store``      the resumable parts store (one JSON file per finished scenario) and the output lock
``execution``  the Dask cluster, chunked tasks, retries, progress, resume: :func:`run_study`
"""

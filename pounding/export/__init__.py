"""Export of models to other programs: an OpenSeesPy script (``pounding export opensees``)."""

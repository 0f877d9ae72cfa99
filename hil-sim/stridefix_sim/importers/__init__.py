"""Importers of real public data sets: each turns a data set's files into a raw-sensor LCM event log
(channels ``IMU``, ``MAG``, ``BARO``, ``WIFI``, ``GNSS`` plus ``TRUTH``) that ``stridefixd --input
lcmlog:FILE`` replays and the analyzer reads.

========  =====================================================================================
msindoor  Microsoft Indoor Location Competition 2.0 sample traces (``msindoor.py``)
gsd       GetSensorData logfiles, the IPIN competition Track 3 format (``gsd.py``)
========  =====================================================================================

``cli.py`` is the ``stridefix import FORMAT ...`` sub-command; a new format is one module plus one
entry in its ``FORMATS`` table.
"""

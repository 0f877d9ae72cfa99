"""StrideFix common: what the simulator and the analyzer both speak, said once.

:mod:`.exits` the exit-status contract of every command; :mod:`.geodesy` WGS-84 and the local tangent
plane; :mod:`.building` the building description's schema (``building.toml``); :mod:`.physics` the
physical constants both sides model (the access points' height); :mod:`.dbc` the board's CAN frames
(``board.dbc``, package data). Nothing here imports the simulator,
the analyzer or the lab.
"""

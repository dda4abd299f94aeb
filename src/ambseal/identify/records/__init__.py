"""ambseal.identify.records: The record of an identification run: its file format, the record in memory and its checks, and the MATLAB files a rig may write.

Internal to :mod:`ambseal.identify`, whose face lists what other packages use.
"""

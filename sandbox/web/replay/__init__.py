"""Recordings after the fact: ``sandbox replay`` in the browser with a timeline, the static
export of one recording, and lesson packs of several.
"""

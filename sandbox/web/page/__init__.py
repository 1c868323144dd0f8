"""The page as viser's client shows it, changed for a class: French words and locale of
viser's own client, keyboard and screen-reader access, the phone and tablet layout, and
the page's side of a shared setup link.
"""

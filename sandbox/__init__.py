"""Interactive teaching sandbox for rigid-body dynamics (course "Dynamique des solides")."""

__version__ = "0.1.0"

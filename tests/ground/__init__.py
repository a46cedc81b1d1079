"""Tests of the modules at the package root: errors, console, files, locks, identity, porosity."""

"""The tests, one folder per part of the package; tests of the whole package at this level."""

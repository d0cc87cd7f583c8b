"""The plan files shipped with the library (package data: YAML and XML, no code)."""

"""RASCAL task layer: configuration, state machine, stations, catalogue and archive."""

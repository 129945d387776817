"""Modules the operators share that are not operators: the background run session, the world
shader's difference layer, and the interactive relocation's input state machine."""

"""The object in the photograph: which pixels of a window show it, told apart from the proxy's guess."""

"""Pictures: the meshcat browser viewer and its offline HTML page, and matplotlib plots."""

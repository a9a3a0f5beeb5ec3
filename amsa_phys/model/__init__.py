"""L0: what a system *is* — templates, parameters, components, data, links, files.

Nothing here knows about time, pymunk or pygame.
"""

"""The original AMSA tool's files: ``.amsacore`` (XMI) and ``.amsatemplate`` (Xtext), in and out."""

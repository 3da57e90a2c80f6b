"""Reference frames: Earth (GCRS/ITRS), Moon (PA/ME), local orbital frames."""

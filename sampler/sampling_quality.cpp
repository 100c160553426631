// sampling quality metrics (being written)

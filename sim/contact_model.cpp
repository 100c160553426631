// contact model (being written)

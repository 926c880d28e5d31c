"""The plant: the C80's MJCF model, its derivation, the reduced models, friction, identification, model card."""

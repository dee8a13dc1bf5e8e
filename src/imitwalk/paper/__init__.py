"""The paper's learner (Chalodhorn et al., IJCAI 2007): posture subspace, gait embedding,
RBF sensory-motor predictor, action selection, and the learning loop around them."""

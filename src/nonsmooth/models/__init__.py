"""Models: vector fields, switching surfaces and regions as compiled scalar functions."""

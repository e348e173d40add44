"""Control design: operating points, linear models, fixed-step runs, controllers in the loop."""

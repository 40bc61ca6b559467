"""Pure NumPy evaluation: basis functions, tensor contraction, rational quotient rule,
differential geometry.  Nothing here imports OCP."""

"""The GG pipeline (paper 4.1): surface design, surface of revolution, geodesic net, map back."""

#version 3.7;
global_settings { max_trace_level 5 assumed_gamma 1.0 ambient_light rgb 0.15 }
background { rgb <0.30, 0.50, 0.85> }
camera { perspective location <0, 1.6, -6> look_at <0, 0.9, 0> angle 58 right x*4/3 }
light_source { <-3, 6, -5> rgb 0.7 }
light_source { <4, 5, -3> rgb 0.45 }
box { <-5, -0.01, -6>, <5, 0, 8>
  pigment { checker rgb <0.9, 0.1, 0.05> rgb <0.95, 0.85, 0.1> }
  finish { diffuse 1 ambient 1 } }
sphere { <0.35, 1.15, -2.3>, 0.75
  pigment { rgbf <1, 1, 1, 0.95> }
  finish { specular 0.6 roughness 0.005 reflection { 0.04, 1 fresnel on } conserve_energy }
  interior { ior 1.5 } }
sphere { <-1.1, 1.0, 0.6>, 1.0
  pigment { rgb <0.05, 0.05, 0.06> }
  finish { specular 0.5 roughness 0.008 reflection 0.85 } }

// The project's shared peer scene for benchmarking (/work/shared/peers/cornell.pov), unchanged below this line.
// Cornell box (published Cornell geometry, mm) with POV-Ray 3.7 radiosity
#version 3.7;
global_settings {
  assumed_gamma 1.0
  max_trace_level 6
  radiosity {
    pretrace_start 0.08 pretrace_end 0.004
    count 400 nearest_count 10 error_bound 0.5
    recursion_limit 4 low_error_factor 0.5 gray_threshold 0
    minimum_reuse 0.015 brightness 1 adc_bailout 0.005
  }
}
// red wall (x~556) must appear on the left: mirror via right -x
camera { perspective location <278,273,-800> look_at <278,273,0> right -x up y angle 39.3 }
#declare White = texture { pigment { rgb <.725,.71,.68> } finish { diffuse 1 ambient 0 emission 0 } }
#declare Red   = texture { pigment { rgb <.63,.065,.05> } finish { diffuse 1 ambient 0 emission 0 } }
#declare Green = texture { pigment { rgb <.14,.45,.091> } finish { diffuse 1 ambient 0 emission 0 } }
#macro Q(A,B,C,D) triangle { A,B,C } triangle { A,C,D } #end
mesh { Q(<552.8,0,0>,<0,0,0>,<0,0,559.2>,<549.6,0,559.2>)
       Q(<556,548.8,0>,<556,548.8,559.2>,<0,548.8,559.2>,<0,548.8,0>)
       Q(<549.6,0,559.2>,<0,0,559.2>,<0,548.8,559.2>,<556,548.8,559.2>)
       Q(<130,165,65>,<82,165,225>,<240,165,272>,<290,165,114>)
       Q(<290,0,114>,<290,165,114>,<240,165,272>,<240,0,272>)
       Q(<130,0,65>,<130,165,65>,<290,165,114>,<290,0,114>)
       Q(<82,0,225>,<82,165,225>,<130,165,65>,<130,0,65>)
       Q(<240,0,272>,<240,165,272>,<82,165,225>,<82,0,225>)
       Q(<423,330,247>,<265,330,296>,<314,330,456>,<472,330,406>)
       Q(<423,0,247>,<423,330,247>,<472,330,406>,<472,0,406>)
       Q(<472,0,406>,<472,330,406>,<314,330,456>,<314,0,456>)
       Q(<314,0,456>,<314,330,456>,<265,330,296>,<265,0,296>)
       Q(<265,0,296>,<265,330,296>,<423,330,247>,<423,0,247>)
       texture { White } }
mesh { Q(<0,0,559.2>,<0,0,0>,<0,548.8,0>,<0,548.8,559.2>) texture { Green } }
mesh { Q(<552.8,0,0>,<549.6,0,559.2>,<556,548.8,559.2>,<556,548.8,0>) texture { Red } }
// area light just below the ceiling; visible emitter quad has no shadow
light_source { <278,548.0,279.5> color rgb <1.0,0.75,0.35>*1.2
  area_light <130,0,0>, <0,0,105>, 6, 6 adaptive 1 jitter
  fade_distance 350 fade_power 2
  looks_like { mesh { Q(<343,548.7,227>,<343,548.7,332>,<213,548.7,332>,<213,548.7,227>)
               translate <-278,-548.0,-279.5>
               texture { pigment { rgb 1 } finish { emission 1 diffuse 0 ambient 0 } } } }
}

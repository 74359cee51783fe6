// A check scene for dcm povray, never tuned on: a courtyard with a tiled
// floor, columns, a low wall, a marble block, two glossy spheres and a
// planter, lit by a sun-like area light and a warm point light. It follows the
// pass convention of docs/POVRAY.md (the camera and Tex() parts are the same
// as scene.pov's).
#version 3.7;

#ifndef (Pass) #declare Pass = 0; #end
#ifndef (Sparse) #declare Sparse = 0; #end
#ifndef (FullW) #declare FullW = image_width; #end
#ifndef (FullH) #declare FullH = image_height; #end
#declare Lit = (Pass = 0 | Pass = 4);

global_settings { assumed_gamma 1.0 ambient_light 1 max_trace_level 5 }

#declare CamLoc = <-3.2, 2.1, -4.6>;
#declare CamAt = <0.4, 0.6, 0.8>;
#declare HFov = 58;
#declare CamFwd = vnormalize(CamAt - CamLoc);
#declare CamRight = vnormalize(vcross(y, CamFwd)) * FullW / FullH;
#declare CamUp = vnormalize(vcross(CamFwd, CamRight));
#declare CamDir = CamFwd * 0.5 * vlength(CamRight) / tan(radians(HFov / 2));

#if (Sparse)
  #include "pixels.inc"
  camera {
    mesh_camera {
      1 0
      mesh {
        #local I = 0;
        #while (I < NPix)
          #local D = vnormalize(CamDir + ((PixX[I] + 0.5) / FullW - 0.5) * CamRight
                                       + (0.5 - (PixY[I] + 0.5) / FullH) * CamUp);
          #if (abs(D.y) < 0.9) #local A = vnormalize(vcross(D, y));
          #else #local A = vnormalize(vcross(D, x)); #end
          #local B = vcross(D, A);
          triangle { A, -0.5 * A - 0.8660254037844386 * B, -0.5 * A + 0.8660254037844386 * B }
          #local I = I + 1;
        #end
        translate CamLoc
      }
    }
    location <0, 0, 0>
    direction <0, 0, 1>
  }
#else
  camera { perspective location CamLoc direction CamDir right CamRight up CamUp }
#end

background { rgb 0 }

#macro Tex(Obj, Shd, Pig, Dif, Amb, Spec, Rough, Refl)
  #switch (Pass)
    #case (1) texture { pigment { rgb Obj } finish { emission 1 ambient 0 diffuse 0 specular 0 } } #break
    #case (2) texture { pigment { rgb Shd } finish { emission 1 ambient 0 diffuse 0 specular 0 } } #break
    #case (3) texture { pigment { Pig } finish { emission 1 ambient 0 diffuse 0 specular 0 } } #break
    #case (4) texture { pigment { rgb 1 } finish { ambient Amb diffuse Dif specular 0 reflection 0 } } #break
    #case (5) texture { pigment { P_Normal } finish { emission 1 ambient 0 diffuse 0 specular 0 } } #break
    #case (6) texture { pigment { rgb (Spec > 0 | Refl > 0) } finish { emission 1 ambient 0 diffuse 0 specular 0 } } #break
    #else
      texture { pigment { Pig }
        finish { ambient Amb diffuse Dif specular Spec roughness Rough reflection Refl } }
  #end
#end

#declare P_Normal = pigment {
  average pigment_map {
    [1 slope { x } color_map { [0 rgb 0] [1 rgb <3, 0, 0>] }]
    [1 slope { y } color_map { [0 rgb 0] [1 rgb <0, 3, 0>] }]
    [1 slope { z } color_map { [0 rgb 0] [1 rgb <0, 0, 3>] }]
  }
}
#declare P_Tiles = pigment {
  checker rgb <0.62, 0.58, 0.50>, rgb <0.30, 0.28, 0.26> scale 0.5
}
#declare P_Stone = pigment { granite color_map { [0 rgb <0.70, 0.68, 0.64>] [1 rgb <0.52, 0.50, 0.47>] } scale 0.6 }
#declare P_Marble = pigment {
  marble turbulence 0.8 color_map { [0 rgb <0.92, 0.90, 0.86>] [0.8 rgb <0.80, 0.78, 0.74>] [1 rgb <0.35, 0.33, 0.32>] }
  scale 0.4
}
#declare P_Blue = pigment { rgb <0.10, 0.22, 0.60> }
#declare P_Gold = pigment { rgb <0.75, 0.55, 0.15> }
#declare P_Clay = pigment { rgb <0.62, 0.30, 0.18> }
#declare P_Leaf = pigment { rgb <0.15, 0.45, 0.12> }
#declare P_Sky = pigment { gradient y color_map { [0 rgb <0.75, 0.82, 0.95>] [1 rgb <0.35, 0.50, 0.85>] } scale 12 }

// 1 floor, 2 back and side walls, 3 columns, 4 low wall, 5 marble block,
// 6 and 7 spheres, 8 planter and bush, 9 the sky dome
plane { y, 0 Tex(1, 1, P_Tiles, 0.8, 0.05, 0.1, 0.05, 0) }
union {
  box { <-6, 0, 3>, <6, 3.5, 3.3> }
  box { <5, 0, -6>, <5.3, 3.5, 3.3> }
  Tex(2, 2, P_Stone, 0.75, 0.05, 0, 0.05, 0)
}
union {
  #for (I, 0, 3)
    cylinder { <-2.5 + I * 1.8, 0, 2.2>, <-2.5 + I * 1.8, 3.0, 2.2>, 0.18 }
    box { <-2.75 + I * 1.8, 0, 1.95>, <-2.25 + I * 1.8, 0.2, 2.45> }
  #end
  Tex(3, 3, P_Stone, 0.75, 0.05, 0.1, 0.05, 0)
}
box { <-1.2, 0, -0.9>, <3.5, 0.45, -0.6> Tex(4, 4, P_Stone, 0.75, 0.05, 0, 0.05, 0) }
box { <0.0, 0, 0.2>, <1.1, 0.7, 1.0> rotate 20 * y Tex(5, 5, P_Marble, 0.7, 0.05, 0.5, 0.01, 0.1) }
sphere { <0.55, 1.05, 0.6>, 0.35 Tex(6, 6, P_Blue, 0.6, 0.05, 0.9, 0.003, 0.3) }
sphere { <-1.6, 0.3, 0.3>, 0.3 Tex(7, 7, P_Gold, 0.5, 0.05, 0.8, 0.005, 0.2) }
union {
  cylinder { <2.6, 0, 0.9>, <2.6, 0.5, 0.9>, 0.4 Tex(8, 8, P_Clay, 0.8, 0.05, 0.1, 0.05, 0) }
  blob {
    threshold 0.6
    #for (I, 0, 11)
      sphere { <2.6 + 0.3 * sin(I * 2.1), 0.75 + 0.04 * I, 0.9 + 0.3 * cos(I * 1.7)>, 0.35, 1 }
    #end
    Tex(8, 9, P_Leaf, 0.8, 0.05, 0, 0.05, 0)
  }
}
sphere { 0, 60 inverse Tex(9, 10, P_Sky, 0, 1, 0, 0.05, 0) }

#if (Lit)
  light_source {
    <-8, 12, -6> color rgb <1.0, 0.97, 0.90> * 1.2
    area_light <1.6, 0, 0>, <0, 0, 1.6>, 12, 12
    adaptive 4
  }
  light_source { <3.8, 1.6, -1.5> color rgb <1.0, 0.70, 0.40> * 0.4 fade_distance 1.5 fade_power 2 }
#end

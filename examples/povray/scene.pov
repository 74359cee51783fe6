// A small furnished room for dcm, rendered as separate passes of one file.
//
//   povray -D -A +FE +W256 +H256 Declare=Pass=N +Iscene.pov +Oout.exr
//
// Pass (a number: Declare= takes numbers only)
//   0  beauty L             lights, diffuse, highlights, reflection
//   1  object ID            emission only: every channel = the object's ID
//   2  shader ID            emission only: every channel = the material's ID
//   3  texture tau          emission only: the diffuse pigment, no lighting
//   4  illumination L_i     every pigment white, diffuse + ambient only
//   5  normal               emission only: slope patterns along x, y, z in
//                           R, G, B: value v = 1 - angle/180 deg, so the
//                           normal's component is -cos(pi * v)
//   6  highlight mask       emission only: 1 where the texture has specular
//                           or reflection, else 0
// With antialiasing off and an area light without `jitter`, L = L_i*tau + L_c
// holds exactly: POV-Ray multiplies the pigment into the diffuse and ambient
// terms only, so L_c = L - L_i*tau is the highlights and reflections.
//
// Sparse = 1 replaces the perspective camera by a mesh_camera with one
// triangle per pixel of the list in "pixels.inc" (written by dcm povray):
//   #declare NPix = N; #declare PixX = array[N] {...}; #declare PixY = array[N] {...};
// Face i is rendered as output pixel (i mod image_width, i div image_width + 1):
// POV-Ray 3.7 moves y to the pixel centre (y - 0.5) before truncating it to a
// face row, so output row r traces face row r - 1 (render from row 2: +SR2).
// Face i's ray is the perspective camera's ray through the centre of pixel
// (PixX[i], PixY[i]) of the FullW x FullH frame (declare both).
#version 3.7;

#ifndef (Pass) #declare Pass = 0; #end
#ifndef (Sparse) #declare Sparse = 0; #end
#ifndef (FullW) #declare FullW = image_width; #end
#ifndef (FullH) #declare FullH = image_height; #end
#declare Lit = (Pass = 0 | Pass = 4);

global_settings { assumed_gamma 1.0 ambient_light 1 max_trace_level 5 }

// ---- camera: explicit vectors, shared by the perspective and mesh cameras --
#declare CamLoc = <1.35, 1.45, -2.55>;
#declare CamAt = <-0.35, 0.72, 1.4>;
#declare HFov = 64;
#declare CamFwd = vnormalize(CamAt - CamLoc);
#declare CamRight = vnormalize(vcross(y, CamFwd)) * FullW / FullH;
#declare CamUp = vnormalize(vcross(CamFwd, CamRight));
#declare CamDir = CamFwd * 0.5 * vlength(CamRight) / tan(radians(HFov / 2));

#if (Sparse)
  #include "pixels.inc"
  camera {
    mesh_camera {
      1 0   // one ray per pixel; distribution 0: one face per pixel
      mesh {
        #local I = 0;
        #while (I < NPix)
          // POV-Ray's perspective ray through the pixel centre (tracepixel.cpp:
          // x0 = (x + 0.5) / W - 0.5, y0 = 0.5 - (y + 0.5) / H).
          #local D = vnormalize(CamDir + ((PixX[I] + 0.5) / FullW - 0.5) * CamRight
                                       + (0.5 - (PixY[I] + 0.5) / FullH) * CamUp);
          #if (abs(D.y) < 0.9) #local A = vnormalize(vcross(D, y));
          #else #local A = vnormalize(vcross(D, x)); #end
          #local B = vcross(D, A);
          // An equilateral triangle of unit size around the origin: its
          // centroid is the ray origin, its normal the ray direction (a large
          // triangle keeps the normal accurate in the mesh's float storage).
          triangle { A, -0.5 * A - 0.8660254037844386 * B, -0.5 * A + 0.8660254037844386 * B }
          #local I = I + 1;
        #end
        translate CamLoc
      }
    }
    location <0, 0, 0>   // no offset of the ray origin along the normal
    direction <0, 0, 1>  // do not reverse the normal
  }
#else
  camera { perspective location CamLoc direction CamDir right CamRight up CamUp }
#end

background { rgb 0 }

// ---- materials --------------------------------------------------------------
// Tex(object ID, shader ID, pigment, diffuse, ambient, specular, roughness, reflection)
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

// the normal pass: average of three slope patterns, each scaled by 3 into its channel
#declare P_Normal = pigment {
  average pigment_map {
    [1 slope { x } color_map { [0 rgb 0] [1 rgb <3, 0, 0>] }]
    [1 slope { y } color_map { [0 rgb 0] [1 rgb <0, 3, 0>] }]
    [1 slope { z } color_map { [0 rgb 0] [1 rgb <0, 0, 3>] }]
  }
}
#declare P_Planks = pigment {
  brick color rgb <0.16, 0.09, 0.05>, color rgb <0.55, 0.36, 0.20>
  brick_size <1.2, 0.5, 0.16> mortar 0.012
  rotate 90 * x
}
#declare P_Wall = pigment { rgb <0.78, 0.76, 0.70> }
#declare P_Ceiling = pigment { rgb 0.85 }
#declare P_Accent = pigment { rgb <0.45, 0.58, 0.66> }
#declare P_Rug = pigment { checker rgb <0.70, 0.15, 0.12>, rgb <0.92, 0.86, 0.70> scale 0.25 }
#declare P_Wood = pigment {
  wood color_map { [0 rgb <0.50, 0.30, 0.15>] [1 rgb <0.30, 0.17, 0.08>] }
  turbulence 0.05 scale <0.06, 0.06, 1> rotate 90 * y
}
#declare P_Red = pigment { rgb <0.70, 0.06, 0.05> }
#declare P_Metal = pigment { rgb 0.35 }
#declare P_Shade = pigment { rgb <0.95, 0.88, 0.70> }
#declare P_Cabinet = pigment { rgb <0.22, 0.36, 0.30> }
#declare P_Picture = pigment {
  bozo color_map { [0 rgb <0.10, 0.20, 0.50>] [0.5 rgb <0.90, 0.70, 0.20>] [1 rgb <0.20, 0.50, 0.20>] }
  scale 0.12
}

// ---- room: x -3..3, y 0..2.8, z -3..3.5 ------------------------------------
// 1 floor (planks)
plane { y, 0 Tex(1, 1, P_Planks, 0.75, 0.03, 0.15, 0.05, 0) }
// 2 walls and ceiling: one object, three shaders
union {
  difference {
    box { <-3.1, -0.1, -3.1>, <3.1, 2.9, 3.6> }
    box { <-3, -0.2, -3>, <3, 3, 3.5> Tex(2, 2, P_Wall, 0.8, 0.03, 0, 0.05, 0) }
    box { <-2.999, 2.0, 3.49>, <2.999, 2.799, 3.51> Tex(2, 3, P_Accent, 0.8, 0.03, 0, 0.05, 0) }
    Tex(2, 2, P_Wall, 0.8, 0.03, 0, 0.05, 0)
  }
  box { <-3.1, 2.8, -3.1>, <3.1, 2.9, 3.6> Tex(2, 4, P_Ceiling, 0.8, 0.03, 0, 0.05, 0) }
}
// 3 rug (checker)
box { <-1.6, 0, -0.6>, <0.8, 0.006, 1.6> Tex(3, 5, P_Rug, 0.8, 0.03, 0, 0.05, 0) }
// 4 table: top and four thin legs
#declare TableTex = Tex(4, 6, P_Wood, 0.7, 0.03, 0.35, 0.01, 0.05)
union {
  box { <-0.9, 0.72, 0.2>, <0.5, 0.76, 1.2> }
  #for (I, 0, 3)
    cylinder { <(I < 2 ? -0.84 : 0.44), 0, (mod(I, 2) = 0 ? 0.26 : 1.14)>,
               <(I < 2 ? -0.84 : 0.44), 0.72, (mod(I, 2) = 0 ? 0.26 : 1.14)>, 0.025 }
  #end
  texture { TableTex }
}
// 5 chair: seat, legs, back rails and thin spindles
union {
  box { <-0.2, 0.44, -0.55>, <0.22, 0.47, -0.15> }
  #for (I, 0, 3)
    cylinder { <(I < 2 ? -0.18 : 0.20), 0, (mod(I, 2) = 0 ? -0.53 : -0.17)>,
               <(I < 2 ? -0.18 : 0.20), (mod(I, 2) = 0 ? 0.98 : 0.44), (mod(I, 2) = 0 ? -0.53 : -0.17)>, 0.016 }
  #end
  box { <-0.18, 0.92, -0.545>, <0.20, 0.98, -0.515> }
  #for (I, 1, 5)
    cylinder { <-0.18 + I * 0.38 / 6, 0.47, -0.53>, <-0.18 + I * 0.38 / 6, 0.92, -0.53>, 0.006 }
  #end
  Tex(5, 6, P_Wood, 0.7, 0.03, 0.35, 0.01, 0.05)
}
// 6 glossy red ball on the table
sphere { <-0.15, 0.96, 0.65>, 0.2 Tex(6, 7, P_Red, 0.6, 0.03, 0.8, 0.004, 0.25) }
// 7 floor lamp: thin metal stand, base and an open shade around a point light
union {
  cylinder { <-2.2, 0, 2.4>, <-2.2, 0.03, 2.4>, 0.18 Tex(7, 8, P_Metal, 0.5, 0.03, 0.6, 0.01, 0.35) }
  cylinder { <-2.2, 0, 2.4>, <-2.2, 1.55, 2.4>, 0.012 Tex(7, 8, P_Metal, 0.5, 0.03, 0.6, 0.01, 0.35) }
  difference {
    cone { <-2.2, 1.45, 2.4>, 0.26, <-2.2, 1.75, 2.4>, 0.16 }
    cone { <-2.2, 1.449, 2.4>, 0.255, <-2.2, 1.751, 2.4>, 0.155 }
    Tex(7, 9, P_Shade, 0.9, 0.03, 0, 0.05, 0)
  }
}
// 8 cabinet against the back wall, 9 picture above it
box { <0.9, 0, 2.95>, <2.5, 0.85, 3.499> Tex(8, 10, P_Cabinet, 0.75, 0.03, 0.2, 0.02, 0) }
box { <1.2, 1.15, 3.47>, <2.2, 1.8, 3.499> Tex(9, 11, P_Picture, 0.8, 0.03, 0, 0.05, 0) }

// ---- lights (lit passes only): a ceiling area light and the lamp's bulb ----
#if (Lit)
  // area light without jitter (deterministic samples, the same in passes 0 and 4)
  light_source {
    <0.2, 2.45, 0.8> color rgb <1.0, 0.96, 0.88> * 1.1
    area_light <1.0, 0, 0>, <0, 0, 0.7>, 17, 17
    adaptive 4  // a 17x17 grid from the start: every sample, no adaptive subdivision
    fade_distance 2.5 fade_power 2
  }
  light_source { <-2.2, 1.6, 2.4> color rgb <1.0, 0.75, 0.45> * 0.5 fade_distance 0.8 fade_power 2 }
#end

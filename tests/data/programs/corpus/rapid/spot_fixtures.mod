%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE SpotFixtures
  PERS tooldata tSpotGun:=[TRUE,[[0.0,120.0,330.0],[1.0000000,0.0000000,0.0000000,0.0000000]],[65,[0,0,100],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata wobjLeft:=[FALSE,TRUE,"",[[1800.0,-350.0,500.0],[1.0000000,0.0000000,0.0000000,0.0000000]],[[0.0,0.0,0.0],[1.0000000,0.0000000,0.0000000,0.0000000]]];
  TASK PERS wobjdata wobjRight:=[FALSE,TRUE,"",[[1800.0,250.0,500.0],[1.0000000,0.0000000,0.0000000,0.0000000]],[[0.0,0.0,0.0],[1.0000000,0.0000000,0.0000000,0.0000000]]];
  CONST robtarget pApproach:=[[181.64,608.41,261.49],[0.0383016,-0.0133204,0.9969255,-0.0670455],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget pSpot1:=[[192.56,636.81,64.01],[0.0294800,-0.0264414,0.9971835,-0.0636932],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget pSpot2:=[[222.69,524.50,79.08],[0.0303902,-0.0143190,0.9985098,-0.0430079],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];

  PROC main()
    MoveJ pApproach,v1000,z50,tSpotGun\WObj:=wobjLeft;
    MoveL pSpot1,v500,fine,tSpotGun\WObj:=wobjLeft;
    SpotL pSpot1,vmax,gun1,tSpotGun\WObj:=wobjLeft;
    MoveL pSpot2,v500,fine,tSpotGun\WObj:=wobjLeft;
    MoveJ pApproach,v1000,z50,tSpotGun\WObj:=wobjLeft;
    ! the same approach point over the right fixture
    MoveJ pApproach,v1000,z50,tSpotGun\WObj:=wobjRight;
    MoveL pSpot1,v500,fine,tSpotGun\WObj:=wobjRight;
  ENDPROC
ENDMODULE

MODULE Welding
    !***********************************************************
    ! Fillet weld along the fixture's edge and around its corner
    ! (re-created for kincal)
    !***********************************************************
    PERS seamdata seamFillet:=[0.5,0.5,[5,0,24,120,0,0,0,0,0],0.5,0.5,0,0,0,[5,0,24,120,0,0,0,0,0],
                               0,1,[5,0,24,120,0,0,0,0,0],0.3,0,[5,0,24,120,0,0,0,0,0],0];
    PERS welddata weldFillet:=[10,0,[5,0,24,120,0,0,0,0,0],[0,0,0,0,0,0,0,0,0]];
    PERS weavedata weaveZig:=[1,0,3,4,0,0,0,0,0,0,0,0,0,0,0];
    VAR triggdata trigGasOff;
    CONST robtarget pWeldApproach:=[[60,40,220],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSeamStart:=[[60,40,140],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSeamMid:=[[160,40,140],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSeamArc:=[[195,55,140],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSeamArcEnd:=[[210,90,140],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSeamEnd:=[[210,190,140],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pRetract:=[[210,190,260],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];

    PROC WeldFillet()
        MoveJ pWeldApproach, v1000, z20, tWeldGun\WObj:=wobjFixture;
        ArcLStart pSeamStart, v200, seamFillet, weldFillet, fine, tWeldGun\WObj:=wobjFixture;
        ArcL pSeamMid, v10, seamFillet, weldFillet\Weave:=weaveZig, z1, tWeldGun\WObj:=wobjFixture;
        ArcC pSeamArc, pSeamArcEnd, v10, seamFillet, weldFillet\Weave:=weaveZig, z1,
            tWeldGun\WObj:=wobjFixture;
        ArcLEnd pSeamEnd, v10, seamFillet, weldFillet, fine, tWeldGun\WObj:=wobjFixture\SeamName:="Fillet_1";
        TriggIO trigGasOff, 0.5\Time\DOp:=doGasPurge, 0;
        TriggL pRetract, v500, trigGasOff, z10, tWeldGun\WObj:=wobjFixture;
    ENDPROC
ENDMODULE

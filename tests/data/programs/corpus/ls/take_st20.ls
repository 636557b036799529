/PROG  TAKE_ST20
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "Take at ST20";
PROG_SIZE	= 2310;
CREATE		= DATE 24-03-11  TIME 08:12:40;
MODIFIED	= DATE 24-03-12  TIME 14:02:16;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 14;
MEMORY_SIZE	= 2750;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  UFRAME_NUM=1 ;
   2:  UTOOL_NUM=2 ;
   3:  PAYLOAD[2] ;
   4:  !take part at ST20 ;
   5:J P[1:HOME] 100% CNT0 ACC100 TB    .10sec,P-SPS    ;
      1:  DO[23]=OFF ;
      2:  TIMER[4]=RESET ;
      3:  TIMER[4]=START ;
       ------ ;
   6:J P[2] 100% CNT100 ACC100    ;
   7:L P[3] 1500mm/sec CNT50 ACC80    ;
   8:L P[4] 300mm/sec FINE    ;
   9:  WAIT (DI[61] AND !DI[62])    ;
  10:  CALL GRIP_CLOSE    ;
  11:L P[4] 300mm/sec FINE Offset,PR[5]    ;
  12:L P[5] 1000mm/sec CNT100 Tool_Offset,PR[6]    ;
  13:J P[6] 100% CNT100 TB   0.00sec,P-SPS    ;
      1:  DO[16]=ON ;
       ------ ;
  14:J P[1:HOME] 100% FINE    ;
/POS
P[1:"HOME"]{
   GP1:
	UF : 1, UT : 2,	
	J1=     0.000 deg,	J2=   -90.000 deg,	J3=    90.000 deg,
	J4=     0.000 deg,	J5=    30.000 deg,	J6=     0.000 deg
};
P[2]{
   GP1:
	UF : 1, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   256.037  mm,	Y =   616.193  mm,	Z =  -781.803  mm,
	W =  -104.002 deg,	P =    -2.894 deg,	R =  -171.182 deg
};
P[3]{
   GP1:
	UF : 1, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   293.632  mm,	Y =   443.322  mm,	Z =  -919.628  mm,
	W =  -103.393 deg,	P =    -6.429 deg,	R =  -169.832 deg
};
P[4]{
   GP1:
	UF : 1, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   287.258  mm,	Y =   305.527  mm,	Z =  -950.229  mm,
	W =  -103.866 deg,	P =    -8.052 deg,	R =  -171.156 deg
};
P[5]{
   GP1:
	UF : 1, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   315.506  mm,	Y =   488.884  mm,	Z =  -769.015  mm,
	W =  -106.317 deg,	P =    -4.788 deg,	R =  -171.773 deg
};
P[6]{
   GP1:
	UF : 1, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   304.327  mm,	Y =   664.506  mm,	Z =  -408.463  mm,
	W =  -111.216 deg,	P =    -1.484 deg,	R =  -173.651 deg
};
/END
